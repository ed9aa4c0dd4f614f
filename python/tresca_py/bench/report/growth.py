"""Section 4: growth of time and peak memory with the number of unknowns (bench_elastic.toml)."""
import os

import numpy as np

from tresca_py.bench.report.measure import ELASTIC, Rec, fmt_t, med
from tresca_py.common import BIN


def growth_section(b):
    print("== 4. growth with DOF", flush=True)
    b.md += ["## 4. Growth of time and peak memory with the number of unknowns", "",
             "Scene `verification/bench/bench_elastic.toml`: plain plane-strain elasticity (no contact) on the "
             "unit square, structured cells [4,4] refined k times (n = 4·2^k cells a side, 2n² triangles), clamped "
             "left, non-separable traction on the right, so each step is a load assembly + one pair of triangular "
             "solves. One step: `run --refine k --steps 1 -q` (no output). Five steps: `--steps 5 -o out.h5 --force "
             "-q`; "
             "the step time is the median of the 5 per-step wall times the file records (compute only, without "
             "writing). Peak memory = max RSS from `/usr/bin/time -f %M`. "
             f"Repeats: {b.R} up to refine 6, 1 at refine ≥ 7 (a run takes minutes there).", "",
             "| k | unknowns | 1 step: total | 1 step: peak RSS | set-up asm / fact / superposition+cond | step "
             "compute (median of 5) | "
             "5 steps written: total | peak RSS | load |", "|---|---|---|---|---|---|---|---|---|"]
    for k in range(2, b.gmax + 1):
        growth_row(b, k)
    growth = b.growth
    if len(growth) >= 2:
        expo = growth_exponents(growth)
        b.md += ["", f"Observed exponents between the two largest sizes (time ∝ n^p): assembly p = {expo(3, 1):.2f}, "
                 f"factorisation p = {expo(3, 2):.2f}, step p = {expo(4):.2f}, peak RSS p = {expo(2):.2f}.", ""]


def growth_row(b, k):
    """One row of section 4: bench_elastic.toml at refine k, one step and five steps written."""
    reps = b.R if k <= 6 else 1
    one = Rec([BIN, "run", ELASTIC, "--refine", str(k), "--steps", "1", "-q"], reps, mem=True)
    h5 = os.path.join(b.tmp, f"growth_{k}.h5")
    five = Rec([BIN, "run", ELASTIC, "--refine", str(k), "--steps", "5", "-q", "-o", h5, "--force",
                "--frame-every", "5"], reps, mem=True, h5=h5)
    os.remove(h5)
    st = one.setup
    step = med(five.step_walls)
    b.growth.append((one.info["unknowns"], one.wall, med(one.rss), st, step, five.wall, med(five.rss)))
    b.md.append(f"| {k} | {one.info['unknowns']} | {fmt_t(one.wall)} | {med(one.rss) / 1024:.0f} MB | "
                f"{fmt_t(st[1])} / {fmt_t(st[2])} / {fmt_t(st[3] + st[4])} | {fmt_t(step)} | {fmt_t(five.wall)} | "
                f"{med(five.rss) / 1024:.0f} MB | {one.load}, {five.load} |")
    b.csvrows.append(dict(section="growth", refine=k, dofs=one.info["unknowns"], steps=1, mode="solve",
                          wall=one.wall, setup_asm=st[1], setup_fact=st[2], setup_cond=st[3], per_step=step,
                          rss_kb=med(one.rss), load=one.load))
    print(b.md[-1], flush=True)


def growth_exponents(growth):
    """p(i[, j]): the exponent of growth-row field i (entry j of it) against the unknowns, last two rows."""
    (n0, *_), (n1, *_) = growth[-2], growth[-1]

    def p(i, j=None):
        hi = growth[-1][i] if j is None else growth[-1][i][j]
        lo = growth[-2][i] if j is None else growth[-2][i][j]
        return np.log(hi / lo) / np.log(n1 / n0)
    return p

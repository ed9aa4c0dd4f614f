"""make bench: performance of tresca-cr (issue 7) -> reference/performance.md (+ reference/performance.csv).

    .venv/bin/python verification/bench/report.py [--repeats 5] [--quick] [--max-refine-growth 7] [--no-python]
                                                  [--no-perf]

Every number is the median of --repeats runs (default 5) of the release binary as a process, timed from
Python with time.perf_counter (process start to exit), next to what the CLI itself prints (its wall time
and the set-up split mesh/assembly/factorisation/condensation). The 1-minute load average is recorded
with every measurement: the machine is shared, so absolute times carry that noise.

Sections:
 1. Example 5.1 (verification/cases/paper_example_5_1.toml) at every level of the paper's Table 5.1
    (refine k = 0..4 -> n = 2..32, N = 40*2^k steps), ssn and uzawa, solve-only (no -o) and written in full
    (-o out.h5 --force; and with --commit-interval 10, i.e. one commit at the end); total, per step,
    iterations per step, set-up split.
 2. The same problem run by scripts/skfem_solve.py and scripts/dolfinx_solve.py (process wall, their own
    total without the Python start-up), as ratios to the Rust times; the results are compared with
    scripts/compare.py (equal accuracy = the same discrete solution to ~1e-11).
 3. The floor of a step: the same mesh without contact and with a non-separable boundary traction, so each
    step is one (boundary) load assembly + one pair of triangular solves with the reused factor; the
    factorisation cost.
 4. Growth with DOF: verification/bench/bench_elastic.toml (plain elasticity, unit square, cells [4,4],
    refine 2..7 -> 25k..1.57M unknowns), one step (no output) and five steps (written, per-step wall times
    read back from tresca/steps/wall_time), time and peak RSS (/usr/bin/time -f %M).
 5. perf profile of the Example 5.1 finest run (solve-only and written).
 6. Manufactured-solution runs (issue 13): mms_stop refine 5 (64 steps), verification/bench/bench_mms_poly.toml
    (196,608 unknowns, 80 steps), mms_front refine 2 (256 steps), Example 5.1 n = 64 (refine 5, 1280 steps),
    all with true errors at every node where the scene has [exact]; process wall and CPU time (user + sys of
    the child), the set-up split; the expression throughput of the longest expression of verification/cases/
    (probes/expr_throughput.rs, one thread: exmex's interpreter against the compiled program); mms_stop
    refine 4 side by side with scripts/skfem_solve.py and scripts/dolfinx_solve.py (the three run in
    interleaved rounds, so a drift of the machine's speed affects them alike); a perf profile of
    mms_stop refine 5.
"""
import argparse

from tresca_py.bench.report.context import header_section, start
from tresca_py.bench.report.ex51 import ex51_section
from tresca_py.bench.report.floor import floor_section
from tresca_py.bench.report.growth import growth_section
from tresca_py.bench.report.mms import mms_section
from tresca_py.bench.report.perf import perf_section
from tresca_py.bench.report.python_solvers import python_section
from tresca_py.bench.report.targets import splice_section_6, targets_section, write_report


def parse_args(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="levels 0..2, growth to refine 4, 3 repeats")
    ap.add_argument("--max-refine-growth", type=int, default=7)
    ap.add_argument("--no-python", action="store_true")
    ap.add_argument("--no-perf", action="store_true")
    ap.add_argument(
        "--mms-only",
        action="store_true",
        help="only section 6 (issue 13): replaces section 6 and its target rows in reference/performance.md",
    )
    return ap.parse_args(argv)


def main(argv=None):
    b = start(parse_args(argv))
    header_section(b)
    if b.args.mms_only:
        tg = mms_section(b)
        splice_section_6(b, tg)
        print_targets(tg)
        return
    ex51_section(b)
    python_section(b)
    floor_section(b)
    growth_section(b)
    perf_section(b)
    tg13 = mms_section(b)
    tg = targets_section(b, tg13)
    write_report(b)
    print_targets(tg)


def print_targets(tg):
    for t, m, ok in tg:
        print(f"[{'PASS' if ok else 'FAIL'}] {t}: {m}")

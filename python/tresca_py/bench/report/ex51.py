"""Section 1: Example 5.1 at every level of the paper's Table 5.1, ssn and uzawa, solve-only and written."""
import os

from tresca_py.bench.report.measure import EX51, Rec, fmt_t, med
from tresca_py.common import BIN


def ex51_section(b):
    print("== 1. Example 5.1 at the levels of Table 5.1", flush=True)
    b.md += ["## 1. Example 5.1 at every level of the paper's Table 5.1", "",
             "`tresca-cr run verification/cases/paper_example_5_1.toml --refine k --steps 40·2^k --solver S` "
             "(solve-only) and the same with `-o out.h5 --force -q` (written in full: every step's u, contact "
             "state, statistics, ~50 VTKHDF frames, committed (written + flushed) every step, the default); "
             "`write-batched` adds `--commit-interval 10` (commits at most every 10 s: here once at the end); "
             "`write-all-frames` (finest level) adds `--frame-every 1`: every step also a VTKHDF/XDMF frame. "
             "The CLI prints times in whole milliseconds, so for written runs the set-up split is read from the "
             "file's `setup_times` attribute (full precision); for solve-only runs below ~10 ms it is 0/1 ms.", "",
             "| n | N | paper DOF | solver | mode | total (median) | CLI wall | per step | it/step | "
             "set-up mesh / asm / fact / superposition / cond | step compute (from h5, median) | load |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for k in b.levels:
        for solver in ["ssn", "uzawa"]:
            modes = ["solve", "write", "write-batched"] + (["write-all-frames"] if k == max(b.levels) else [])
            for mode in (modes if solver == "ssn" else ["solve", "write"]):
                ex51_row(b, k, solver, mode)
    kf = b.kf
    fin_s, fin_w = b.ex[(kf, "ssn", "solve")], b.ex[(kf, "ssn", "write")]
    b.md += ["", f"Finest level (n = {2 * 2 ** kf}, N = {40 * 2 ** kf}, {fin_s.info['paper_dofs']} paper DOF, "
             f"{fin_s.info['unknowns']} unknowns), ssn: solve-only {fmt_t(fin_s.wall)} of which set-up "
             f"{fmt_t(sum(fin_s.setup))} (assembly {fmt_t(fin_s.setup[1])}, factorisation {fmt_t(fin_s.setup[2])}, "
             "load superposition "
             f"{fmt_t(fin_s.setup[3])}, condensation {fmt_t(fin_s.setup[4])}); the {40 * 2 ** kf} steps take "
             f"{fmt_t(fin_s.per_step * 40 * 2 ** kf)} ({fmt_t(fin_s.per_step)} per step). "
             f"Written in full: {fmt_t(fin_w.wall)}.", ""]


def ex51_row(b, k, solver, mode):
    """One row of section 1: Example 5.1 at refine k with one solver, solve-only or written."""
    N = 40 * 2 ** k
    cmd = [BIN, "run", EX51, "--refine", str(k), "--steps", str(N), "--solver", solver, "-q"]
    h5 = None
    if mode.startswith("write"):
        h5 = os.path.join(b.tmp, f"ex51_{k}_{solver}{'' if mode == 'write' else '_' + mode}.h5")
        cmd += ["-o", h5, "--force"]
    if mode == "write-batched":
        cmd += ["--commit-interval", "10"]
    if mode == "write-all-frames":
        cmd += ["--frame-every", "1"]
    rec = Rec(cmd, b.R, h5=h5)
    b.ex[(k, solver, mode)] = rec
    i = rec.info
    sw = fmt_t(med(rec.step_walls)) if rec.step_walls else "–"
    st = " / ".join(f"{v * 1e3:.1f}" for v in rec.setup) + " ms"
    b.md.append(f"| {2 * 2 ** k} | {N} | {i['paper_dofs']} | {solver} | {mode} | {fmt_t(rec.wall)} | "
                f"{fmt_t(med(rec.cli))} | {fmt_t(rec.per_step)} | {i['iters'] / N:.2f} | {st} | {sw} | "
                f"{rec.load} |")
    b.csvrows.append(dict(section="ex51", refine=k, steps=N, dofs=i["paper_dofs"], solver=solver,
                          mode=mode, wall=rec.wall, cli_wall=med(rec.cli), per_step=rec.per_step,
                          iters_per_step=i["iters"] / N, setup_mesh=rec.setup[0], setup_asm=rec.setup[1],
                          setup_fact=rec.setup[2], setup_sup=rec.setup[3], setup_cond=rec.setup[4], load=rec.load))
    print(b.md[-1], flush=True)

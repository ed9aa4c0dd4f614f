"""Work-precision of tresca-cr on the manufactured cases (issue 7) -> reference/work_precision.{md,csv,png}.

    .venv/bin/python verification/work_precision.py [--repeats 3] [--quick]

For verification/cases/mms_front.toml and mms_stop.toml, every configuration (refine r, steps N, solver,
tolerance) is run twice:
  * once with the scene as it is, for the true error: the CLI's "max over time nodes: energy error";
  * --repeats times on a copy of the scene WITHOUT its [exact] table, for the cost: median process wall
    time (start to exit) — what a user pays for the solution, without the error evaluation.
Families: h (r = 0..R at fixed fine N), k (N sweep at fixed r), joint (r and N refined together:
N = 8·2^r for mms_front; N = 4^(r/... ) see JOINT), tolerance (1e-2 .. 1e-12 at a middle level) for ssn
and uzawa (max_iter raised to 200000 so Uzawa reaches loose and tight tolerances), and ssn vs uzawa on
the joint path. The cheapest configuration reaching each target accuracy is read off all measured points.
"""
import argparse
import atexit
import csv
import os
import re
import shutil
import statistics
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from tresca_py.common import BIN, REF, ROOT, load1, short_path, strip_exact  # noqa: E402
from tresca_py.verify import summary as cli_summary  # noqa: E402
from tresca_py.bench.timing import timed  # noqa: E402
CASES = {
    "mms_front": dict(path="verification/cases/mms_front.toml", h_N=32, h_r=3, k_r=2, k_N=[8, 16, 32, 64, 128, 256],
                      joint=[(0, 8), (1, 16), (2, 32), (3, 64)], tol_level=(2, 32)),
    # mms_stop: N = 4^j keeps theta = frac(N/3) = 1/3 (see the scene's header); joint h -> h/2, k -> k/4
    "mms_stop": dict(path="verification/cases/mms_stop.toml", h_N=16, h_r=3, k_r=2, k_N=[4, 16, 64, 256],
                     joint=[(0, 4), (1, 16), (2, 64), (3, 256)], tol_level=(2, 16)),
}
TOLS = [1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12]


def prepare(case, tmp):
    text = open(os.path.join(ROOT, CASES[case]["path"])).read()
    text = re.sub(r"max_iter\s*=\s*\d+", "max_iter = 200000", text)
    assert "max_iter = 200000" in text
    full = os.path.join(tmp, f"{case}.toml")
    bare = os.path.join(tmp, f"{case}_noexact.toml")
    open(full, "w").write(text)
    open(bare, "w").write(strip_exact(text))
    return full, bare


def command(scene, r, N, solver, tol):
    return [BIN, "run", scene, "--refine", str(r), "--steps", str(N), "--solver", solver, "--tol", f"{tol:g}", "-q"]


def measure(case, full, bare, r, N, solver, tol, repeats, family):
    cmd = command(full, r, N, solver, tol)
    s, p = cli_summary.run(cmd, check=False)
    if p.returncode != 0 or s is None:
        return dict(case=case, family=family, refine=r, steps=N, solver=solver, tol=tol, error=float("nan"),
                    wall=float("nan"), cpu=float("nan"), iters_per_step=float("nan"), dofs=0, load=load1(),
                    note=(p.stderr.strip().splitlines() or ["no summary"])[-1][:160])
    err, _, l2 = cli_summary.max_errors(s)
    it, dofs = s["run"]["iterations"], s["run"]["paper_dofs"]
    walls, cpus, loads = [], [], []
    for _i in range(repeats):
        loads.append(load1())
        t = timed(command(bare, r, N, solver, tol))  # raises with the command and its stderr on failure
        walls.append(t.wall)
        cpus.append(t.cpu)
        if t.wall > 2.0:  # long runs: one timing (the table says how many)
            break
    return dict(
        case=case,
        family=family,
        refine=r,
        steps=N,
        solver=solver,
        tol=tol,
        error=err,
        l2=l2,
        wall=statistics.median(walls),
        cpu=statistics.median(cpus),
        n_timed=len(walls),
        iters_per_step=it / N,
        dofs=dofs,
        load=f"{min(loads):.2f}-{max(loads):.2f}",
        note="",
        cmd=" ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd).replace(
            os.path.relpath(full, ROOT), CASES[case]["path"]
        ),
    )


def measure_all(quick, repeats):
    """Every configuration of every case: a row each (error from the run's --json summary, cost timed)."""
    tmp = tempfile.mkdtemp(prefix="tresca-wp-")
    atexit.register(shutil.rmtree, tmp, True)  # the runs' files are intermediate
    rows = []
    for case, c in CASES.items():
        full, bare = prepare(case, tmp)
        rmax = 2 if quick else c["h_r"]
        todo = []
        todo += [("h", r, c["h_N"] if not quick else 64, "ssn", 1e-12) for r in range(rmax + 1)]
        todo += [("k", c["k_r"] if not quick else 1, N, "ssn", 1e-12) for N in c["k_N"][: 3 if quick else None]]
        joint = c["joint"][: 3 if quick else None]
        todo += [("joint", r, N, s, 1e-12) for r, N in joint for s in ["ssn", "uzawa"]]
        tr, tN = c["tol_level"] if not quick else (1, 16)
        todo += [("tol", tr, tN, s, tol) for s in ["ssn", "uzawa"] for tol in TOLS]
        seen = {}
        for fam, r, N, s, tol in todo:
            key = (r, N, s, tol)
            if key in seen:
                row = dict(seen[key], family=fam)
            else:
                row = measure(case, full, bare, r, N, s, tol, repeats, fam)
                seen[key] = row
            rows.append(row)
            print(f"{case:9} {fam:5} r={r} N={N:5} {s:5} tol={tol:.0e}: error {row['error']:.4e} "
                  f"wall {row['wall']:.4f}s it/step {row['iters_per_step']:.2f} {row['note']}", flush=True)
    return rows


def write_csv(rows, out):
    os.makedirs(out, exist_ok=True)
    keys = [
        "case",
        "family",
        "refine",
        "steps",
        "dofs",
        "solver",
        "tol",
        "error",
        "l2",
        "wall",
        "cpu",
        "n_timed",
        "iters_per_step",
        "load",
        "note",
        "cmd",
    ]
    with open(os.path.join(out, "work_precision.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


def plot(rows, out):
    """CPU against the true error, one panel per case."""
    fig, axes = plt.subplots(1, len(CASES), figsize=(13, 5.2))
    style = {("h", "ssn"): ("o-", "C0"), ("k", "ssn"): ("s-", "C1"), ("joint", "ssn"): ("^-", "C2"),
             ("joint", "uzawa"): ("v--", "C3"), ("tol", "ssn"): ("D:", "C4"), ("tol", "uzawa"): ("x:", "C5")}
    for ax, case in zip(axes, CASES, strict=False):
        for (fam, s), (mk, col) in style.items():
            pts = [(r["cpu"], r["error"]) for r in rows if r["case"] == case and r["family"] == fam
                   and r["solver"] == s and r["error"] == r["error"]]
            if pts:
                ax.loglog(*zip(*pts, strict=False), mk, color=col, label=f"{fam} ({s})")
        ax.set_xlabel("CPU time (s, user + sys, median, process, without error evaluation)")
        ax.set_ylabel("true energy error, max over time nodes")
        ax.set_title(case)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "work_precision.png"), dpi=120)


def markdown(rows, repeats):
    md = ["# Work–precision on the manufactured cases (issues 7 and 13)", "",
          "Generated by `.venv/bin/python verification/work_precision.py`. True error = `run.max_errors.energy` "
          "of the CLI's --json summary (run with the scene's [exact]); wall = median of "
          f"{repeats} process runs (1 when a run takes > 2 s) of the same command on the scene without [exact] (the "
          "error evaluation "
          "is not part of the cost), `max_iter` raised to 200000; CPU = user + sys time of those runs (median), the "
          "cost measure that does not include waiting for a core on the shared machine (the conclusions use it). "
          "Machine: "
          f"{os.cpu_count()} cores, shared; 1-min load per row.", "",
          "Families: **h** = refine r at fixed N; **k** = N at fixed r; **joint** = both refined "
          "(mms_front: N = 8·2^r; mms_stop: N = 4^(r+1), the θ = 1/3 sequence of its header); **tol** = `--tol` "
          "at a fixed level, ssn and uzawa.", "", "![work-precision](work_precision.png)", ""]
    for case in CASES:
        md += [f"## {case}", "", "| family | r | N | paper DOF | solver | tol | energy error | L2 error | wall | CPU | "
                                 "runs timed | it/step | load | note |",
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            if r["case"] != case:
                continue
            md.append("| "
                      f"{r['family']} | {r['refine']} | {r['steps']} | {r['dofs']} | {r['solver']} | {r['tol']:.0e} | "
                      f"{r['error']:.4e} | "
                      f"{r.get('l2', float('nan')):.3e} | "
                      f"{r['wall'] * 1e3:.1f} ms | {r['cpu'] * 1e3:.1f} ms | {r.get('n_timed', 0)} | "
                      f"{r['iters_per_step']:.2f} | {r['load']} | {r['note']} |")
        ok = [r for r in rows if r["case"] == case and r["error"] == r["error"]]
        md += [
            "",
            "Cheapest measured configuration reaching a target accuracy:",
            "",
            "| target energy error | cheapest (CPU) | its error | CPU | wall | command |",
            "|---|---|---|---|---|---|",
        ]
        errs = sorted(r["error"] for r in ok)
        targets = sorted({float(f"{e:.0e}") for e in [errs[-1] * 0.9, errs[len(errs) // 2], errs[len(errs) // 4],
                                                       errs[0] * 1.05]}, reverse=True)
        for tgt in targets:
            cand = [r for r in ok if r["error"] <= tgt]
            if not cand:
                continue
            b = min(cand, key=lambda r: r["cpu"])
            md.append(f"| {tgt:.0e} | r={b['refine']}, N={b['steps']}, {b['solver']}, tol {b['tol']:.0e} | "
                      f"{b['error']:.3e} | {b['cpu'] * 1e3:.1f} ms | {b['wall'] * 1e3:.1f} ms | `{b.get('cmd', '')}` |")
        md.append("")
    return md + conclusions(rows)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=REF, help="where the CSV, plot and Markdown go (default reference/)")
    args = ap.parse_args(argv)
    rows = measure_all(args.quick, args.repeats)
    write_csv(rows, args.out)
    plot(rows, args.out)
    with open(os.path.join(args.out, "work_precision.md"), "w") as f:
        f.write("\n".join(markdown(rows, args.repeats)) + "\n")
    print(f"wrote {short_path(args.out)}/work_precision.{{md,csv,png}}")


def conclusions(rows):
    """The conclusions, computed from the measured rows (so they follow the numbers when regenerated)."""
    import math
    out = ["## Conclusions (from the numbers above)", ""]
    floor = min(r["cpu"] for r in rows if r["cpu"] == r["cpu"])
    out.append(f"* The cheapest process of all takes {floor * 1e3:.1f} ms CPU: process start, scene reading and set-up "
               "bound the cost of the coarse levels, so the coarse end of every curve is flat.")
    for case in CASES:
        ok = [r for r in rows if r["case"] == case and r["error"] == r["error"] and r["cpu"] == r["cpu"]]
        h = sorted((r for r in ok if r["family"] == "h"), key=lambda r: r["dofs"])
        k = sorted((r for r in ok if r["family"] == "k"), key=lambda r: r["steps"])
        if len(h) >= 2:
            a, b = h[-2], h[-1]
            p = math.log(b["cpu"] / a["cpu"]) / math.log(b["dofs"] / a["dofs"])
            q = math.log(a["error"] / b["error"]) / math.log(b["dofs"] / a["dofs"])
            out.append(f"* {case}, h family (N = {b['steps']}): from {a['dofs']} to {b['dofs']} DOF the cost grows as "
                       f"DOF^{p:.2f} "
                       f"({a['cpu'] * 1e3:.0f} → {b['cpu'] * 1e3:.0f} ms CPU) while the energy error falls as "
                       f"DOF^-{q:.2f}.")
        if len(k) >= 2:
            a, b = k[0], k[-1]
            per = (b["cpu"] - a["cpu"]) / (b["steps"] - a["steps"])
            out.append(f"* {case}, k family (r = {b['refine']}): a step costs {per * 1e6:.0f} µs at {b['dofs']} DOF "
                       f"({a['steps']} → {b['steps']} steps: {a['cpu'] * 1e3:.1f} → {b['cpu'] * 1e3:.1f} ms CPU); the "
                       f"error goes {a['error']:.2e} → {b['error']:.2e}.")
        tol = [r for r in ok if r["family"] == "tol"]
        for solver in ("ssn", "uzawa"):
            t = sorted((r for r in tol if r["solver"] == solver), key=lambda r: -r["tol"])
            if len(t) >= 2:
                out.append(f"* {case}, {solver}: tolerance {t[0]['tol']:.0e} → {t[-1]['tol']:.0e} costs "
                           f"{t[0]['cpu'] * 1e3:.1f} → {t[-1]['cpu'] * 1e3:.1f} ms CPU ({t[0]['iters_per_step']:.1f} → "
                           f"{t[-1]['iters_per_step']:.1f} iterations per step); the energy error is "
                           f"{t[0]['error']:.3e} → {t[-1]['error']:.3e}.")
        if ok:
            best = min(ok, key=lambda r: r["error"] / 1.0)
            out.append("* "
                       f"{case}: the most accurate measured run "
                       f"(r={best['refine']}, N={best['steps']}, {best['solver']}) "
                       "reaches "
                       f"{best['error']:.3e} in {best['cpu'] * 1e3:.0f} ms CPU; the cheapest configurations per "
                       "accuracy are in the table above each case's rows.")
    out.append("")
    return out

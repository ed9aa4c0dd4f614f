"""Issue 15: `tresca-cr plan` checked against the truth -> reference/planner.md (+ reference/planner.csv).

    .venv/bin/python verification/planner.py [--quick] [--costs] [--json OUT] [--md FILE] [--cases mms_front ...]

(verification/planner.py is the entry point.) Every number comes from the CLI's --json summary
(src/cli/summary.rs): a run's true error is its `run.max_errors.energy`, a plan its `plan.plan` and `plan.tol`.

No requirement depends on a time. PL1 and PL2 compare the plans with the truth. The costs (CPU seconds) —
the plan's against the cheapest grid configuration, the planner's own against the plan's — are measured
only with --costs (`make bench`) and reported as benchmark rows beside the requirements, not as pass/fail:
on a shared machine a ratio of CPU times moves by tens of per cent from run to run (PL4 once failed at 0.204
against 0.2 by noise alone).

For each manufactured case (exact solution known):
 1. Brute-force grid, the work-precision data of this check: refine r = 0..R and steps N = N_s·2^j (N_s the
    scene's steps: the fewest a plan offers), each configuration run as a plan runs it (semismooth Newton,
    tol 1e-6: `tresca_py/verify/planner_grid.py`), once, with the scene's [exact] for its true error (the
    CLI's "max over time nodes: energy error"), and only when a question of the check needs it (the finest
    configuration; PL5's cheapest configuration meeting a target, searched in increasing work, so exactly the
    full grid's answer). With --costs every configuration is also run on the scene without [exact] for its
    cost: CPU time (user + sys) of the process, median of 3 (one run when it takes over 2 s). CPU time, not
    wall, because the machine is shared: waiting for a core is not a cost of the method.
 2. Sweep: nine targets a quarter decade apart, spanning two decades and ending at the finest quarter-decade
    value 10^(-j/4) that the finest grid configuration (refine R, the most steps) meets with a 10 % margin
    (MARGIN: so that the truth decides every target robustly; for the default grids 3.16e-1 .. 3.16e-3, or
    1.78e-1 .. 1.78e-3 where refine 6 reaches below 1.6e-3). For each, `tresca-cr plan SCENE --target T`
    (its CPU time is the planner's own cost: all pilot runs; median of 3 as above); the plan (refine,
    steps, ssn, tol) is the grid's configuration when its tol is the grid's (true error with [exact], cost
    without: the same command as the planned level of `plan --run`), else run like one. Where the adaptive
    route is recommended, `plan --target T --run` runs it and its last level's true error is the plan's.
 3. Requirements (per case):
    PL1 the plan meets the target in truth (true error <= target) for every target (issue 42: 0 misses; with
        --run the route `plan --run` recommends and runs, uniform or adaptive, is the one checked);
    PL2 it never misses by more than 25 % (true error <= 1.25 target);
    and with --costs, benchmark rows (no pass/fail): the plan's cost against the cheapest grid configuration
    whose true error meets the target (issue 15 asked for within 2x), and the planner's own cost against the
    plan's for the targets whose plan lies at the two finest refinements the sweep reaches (issue 15 asked for
    below 20 %, issue 32 for below 5 %).
 4. Example 5.1 (no exact solution): the plans for targets 1e-4 (run with --run: the achieved estimate) and
    1e-5, against what the paper's pairing N = 20 n (n = 2^(r+1)) costs at the same mesh.
"""
import argparse
import atexit
import csv
import math
import os
import shutil
import statistics
import tempfile
import time

from tresca_py.common import BIN, REF, ROOT, case, cmdline, load1, run
from tresca_py.verify import summary as cli_summary
from tresca_py.verify.harness import Harness, out_dir
from tresca_py.verify.planner_grid import GRID_TOL, Cache, Grid, Runner
from tresca_py.verify.planner_md import case_md, csv_rows, work
from tresca_py.bench.timing import timed

# grid per case: steps N_s·2^j for j < len; refinements 0..R
CASES = {
    "mms_front": dict(doublings=3, R=6),
    "mms_rotated": dict(doublings=4, R=6),
    "mms_stop": dict(doublings=7, R=6),
    # issue 42: the corner-singular case (the planner's order bound 0.5445; its adaptive route) and Dirichlet
    # data with a slip front; the time grid does not move their answers (exact at the nodes / 64 steps)
    "mms_lshape": dict(doublings=1, R=6),
    "mms_data_front": dict(doublings=1, R=5),
    # issue 42: every other manufactured case with an exact solution (R = 5 keeps the sweep's wall modest: its
    # targets end where the grid reaches); the stops' time errors need the longer time families
    "mms_elastic": dict(doublings=1, R=5),
    "mms_data_cep": dict(doublings=1, R=5),
    "mms_data_stop": dict(doublings=5, R=5),
    "mms_stick_to_slip": dict(doublings=1, R=5),
    "mms_signorini_coulomb": dict(doublings=1, R=5),
    "mms_signorini_incompressible": dict(doublings=1, R=5),
    "mms_signorini_moving": dict(doublings=1, R=5),
    "mms_signorini_stop": dict(doublings=6, R=5),
    "elastic_rect": dict(doublings=1, R=5),
    "elastic_rotated": dict(doublings=1, R=5),
    "near_incompressible": dict(doublings=1, R=5),
}


# PL5 (not PL3, the CPU-time requirement issue 32 removed): the plan's work within this factor of the cheapest grid
# configuration meeting the target (issue 15's "within 2x", issue 42's requirement; in work units, not CPU time:
# no requirement depends on a time)
WORK_RATIO = 2.0

# A target must be met by a grid point with this margin (error <= MARGIN x target) to end a sweep: the truth
# then decides it robustly. A target that only the grid's best point meets, by less than the planner's
# prediction uncertainty (the 10 % of the asymptotic-range check), tests the grid's granularity (x4 cost per
# refinement or time-family step), not the planner.
MARGIN = 0.9


def targets(finest, count):
    """`count` targets a quarter decade apart ending at the finest 10^(-j/4) that the grid's finest
    configuration (error ``finest``) meets with the margin MARGIN."""
    j = math.floor(-4 * math.log10(finest / MARGIN) + 1e-9)
    return [10 ** (-(j - i) / 4) for i in reversed(range(count))]
EX51 = case("paper_example_5_1")


def median_cost(cmd):
    """Median CPU and wall seconds of up to 3 runs (one when it takes over 2 s), the max 1-minute load."""
    cpus, walls, loads = [], [], []
    for _ in range(3):
        loads.append(load1())
        t = timed(cmd)
        cpus.append(t.cpu)
        walls.append(t.wall)
        if t.wall > 2.0:
            break
    return statistics.median(cpus), statistics.median(walls), max(loads)


def scene_steps(path):
    """The scene's time steps (`tresca-cr check --json`)."""
    s, _ = cli_summary.run([BIN, "check", path])
    return s["check"]["steps"]


def binary_version():
    return run([BIN, "--version"])[0].stdout.strip()


def plan(scene, target, extra=(), costs=False):
    """Run `tresca-cr plan` (with ``--run`` in ``extra``: also the route it recommends); returns
    (its summary's plan part, planner CPU s or None, planner wall s or None,
    command, its printed report for the Markdown). The planner's cost is measured (median of 3 as for a
    configuration) only with ``costs``."""
    cmd = [BIN, "plan", scene, "--target", f"{target:.6g}"] + list(extra)
    s, p = cli_summary.run(cmd)
    cpu, wall = (median_cost([c for c in cmd if c != "--run"])[:2] if costs else (None, None))
    return s["plan"], cpu, wall, cmd, p.stdout


def adaptive_run(runner, p, costs):
    """The adaptive route that `plan --run` ran (None when the uniform route was recommended or nothing ran):
    its true error (the last level's), levels and unknowns; with ``costs`` the CPU of the same loop (the same
    levels: the meshes are deterministic) on the scene without [exact]."""
    a = p.get("adaptive") or {}
    if a.get("choice") != "adaptive" or not a.get("run"):
        return None
    last = a["run"][-1]
    row = dict(route="adaptive", refine=f"adapt {len(a['run'])} lv", steps=a["steps"], tol=p["tol"],
               pred_error=last["estimate"], error=last["error"], unknowns=last["unknowns"],
               work=sum(work(lv["unknowns"], a["steps"]) for lv in a["run"]))
    if costs:
        cmd = [BIN, "adapt", runner.bare, "--levels", len(a["run"]), "--theta", 0.5, "--steps", a["steps"]]
        row["cpu"], row["wall"], _ = median_cost(cmd)
    return row


def plan_row(runner, grid, t, costs, run_plans):
    """One target of the sweep: the plan and the truth about it. The plan is made without ``--run``; the
    uniform route's run is the grid's configuration (the same command, module doc of planner_grid); only
    where the adaptive route is recommended does `plan --run` run it (its loop's true errors)."""
    p, pcpu, pwall, cmd, _ = plan(runner.full, t, costs=costs)
    if run_plans and (p.get("adaptive") or {}).get("choice") == "adaptive":
        p, _, _, cmd, _ = plan(runner.full, t, ["--run"])
    meets = [g for g in grid.rows() if g["error"] <= t]
    cheapest = min(meets, key=lambda g: g["cpu"], default=None) if costs else None
    # PL5 compares with the cheapest configuration meeting the target with the margin MARGIN: one that meets
    # it by less is found only by a prediction better than the pilots' 10 % (the sweep's targets, above)
    row = dict(case=runner.name, target=t, planner_cpu=pcpu, planner_wall=pwall, plan_cmd=cmdline(cmd),
               cheapest=cheapest, cheapest_work=grid.cheapest(MARGIN * t))
    best, adaptive = p["plan"], adaptive_run(runner, p, costs) if run_plans else None
    if adaptive is not None:
        row.update(refused=False, pilot_wall=p["pilot_wall"], pred_wall=p["adaptive"]["adaptive_wall"],
                   run_cmd=cmdline(cmd), **adaptive)
    elif best is None:
        row.update(refused=True)
    else:
        r, n, tol = best["refine"], best["steps"], p["tol"]
        got = grid.at(r, n) if tol == GRID_TOL and n in grid.steps and r in grid.refines else runner.config(r, n, tol)
        row.update(refused=False, route="uniform", refine=r, steps=n, tol=tol, pred_error=best["error"],
                   pred_wall=best["wall"], work=work(got["unknowns"], n),
                   pilot_wall=p["pilot_wall"], error=got["error"], cpu=got.get("cpu"), wall=got.get("wall"),
                   run_cmd=got["cmd"])
    return row


def sweep_case(name, spec, tmp, quick, cache, costs, run_plans=False):
    """The grid (run on demand: planner_grid) and the sweep of one case."""
    runner = Runner(name, tmp, cache, median_cost if costs else None)
    ns = scene_steps(runner.full)
    rmax = 4 if quick else spec["R"]
    steps = [ns * 2 ** j for j in range(min(spec["doublings"], 3) if quick else spec["doublings"])]
    grid = Grid(runner, rmax, steps)
    if costs:
        grid.everything()  # the cheapest configuration by CPU time: every one is measured
    sweep = []
    for t in targets(grid.finest()["error"], 5 if quick else 9):
        row = plan_row(runner, grid, t, costs, run_plans)
        sweep.append(row)
        print(f"  sweep {name} target {t:.3e}: " + ("refused" if row["refused"] else
              f"{row['route']} r={row['refine']} N={row['steps']} tol={row['tol']:g}: true {row['error']:.4e} "
              f"({row['error'] / t:.3f} of target)"), flush=True)
    return grid.rows(), sweep, steps


def requirements(hs, name, sweep, grid_cmd):
    """PL1, PL2 and PL5 of one case, recorded in the harness ``hs``."""
    planned = [s for s in sweep if not s["refused"]]
    met = [s for s in planned if s["error"] <= s["target"]]
    frac = len(met) / len(sweep)
    worst = max((s["error"] / s["target"] for s in planned), default=float("inf"))
    ref = "reference/planner.md"
    hs.require(f"PL1-{name}", frac == 1.0, f"{len(met)}/{len(sweep)} targets met ({100 * frac:.0f} %); "
               f"{len(sweep) - len(planned)} refused",
               statement=f"{name}: the plan shall meet the target in truth for every target of the sweep (issue 42: "
                         "0 misses, on both routes)",
               command=grid_cmd, reference=ref)
    hs.require(f"PL2-{name}", len(planned) == len(sweep) and worst <= 1.25, f"worst true/target {worst:.3f}",
               statement=f"{name}: the plan shall never miss the target by more than 25 %", command=grid_cmd,
               reference=ref)
    ratios = [s["work"] / s["cheapest_work"]["work"] for s in planned]
    hs.require(f"PL5-{name}", len(planned) == len(sweep) and max(ratios, default=float("inf")) <= WORK_RATIO,
               f"plan work / cheapest grid work: max {max(ratios, default=float('nan')):.2f}, median "
               f"{statistics.median(ratios) if ratios else float('nan'):.2f} over {len(ratios)} targets",
               statement=f"{name}: the plan (the route `plan --run` runs) shall cost at most {WORK_RATIO:g}× the "
                         f"cheapest grid configuration that meets the target with the margin {MARGIN:g}, in work units "
                         "n^1.5 + N·n·ln n (tresca_py/verify/planner_md.py; issue 42)", command=grid_cmd, reference=ref)


def example51(tmp, quick, costs):
    """Plans for Example 5.1; with ``costs`` also the CPU of the plan against the paper's pairing N = 20 n at
    the planned mesh."""
    lines = []
    for t in ([1e-4] if quick else [1e-4, 1e-5]):
        run_it = t == 1e-4 and not quick
        p, pcpu, _, cmd, out = plan(EX51, t, ["--run"] if run_it else [], costs=costs)
        cost = f" (planner CPU {pcpu:.2f} s{', with the run' if run_it else ''})" if costs else ""
        lines.append(f"### target {t:g}\n\n`{cmdline(cmd)}`{cost}:\n\n```\n{out.strip()}\n```\n")
        best = p["plan"]
        if best is not None and costs:
            r, n = best["refine"], best["steps"]
            rows = []
            for label, steps in [("plan", n), ("paper's pairing N = 20 n", 40 * 2 ** r)]:
                c = [BIN, "run", EX51, "--refine", r, "--steps", steps, "-q"]
                cpu, wall, _ = median_cost(c)
                rows.append("| "
                            f"{label} | {r} | {2 ** (r + 1)} | {steps} | {cpu:.2f} s | {wall:.2f} s | `{cmdline(c)}` |")
            lines.append("| run | refine | n | steps | CPU | wall | command |\n|---|---|---|---|---|---|---|\n"
                         + "\n".join(rows) + "\n")
    if not costs:
        return "\n".join(lines)
    # the paper's finest level (n = 32, N = 640), solve-only and written in full, against the plan's steps there
    rows = []
    h5 = os.path.join(tmp, "ex51.h5")
    for steps in [640, 40]:
        for written in [False, True]:
            c = [BIN, "run", EX51, "--refine", 4, "--steps", steps, "-q"] + (["-o", h5, "--force"] if written else [])
            cpus = sorted(timed(c).cpu for _ in range(3))
            rows.append("| "
                        f"{steps} | "
                        f"{'written (-o, per-step commits)' if written else 'solve-only'} | {cpus[1]:.3f} s | "
                        f"`{cmdline(c).replace(h5, 'out.h5')}` |")
    lines.append("### The paper's finest level (refine 4, n = 32)\n\nThe paper pairs N = 20 n steps with each mesh; "
                 "the "
                 "data need the scene's 40 (the time grids do not change the answer, above). CPU time, median of 3:\n\n"
                 "| steps | mode | CPU | command |\n|---|---|---|---|\n" + "\n".join(rows) + "\n")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="refine <= 4, 5 targets, fewer steps (for make test)")
    ap.add_argument("--costs", action="store_true", help="also measure CPU costs (make bench; no pass/fail)")
    ap.add_argument("--json", help="write the requirement list here")
    ap.add_argument("--md", default=os.path.join(REF, "planner.md"))
    ap.add_argument("--csv", default=os.path.join(REF, "planner.csv"), help="with --costs: the sweep's rows")
    ap.add_argument("--cases", nargs="*", default=list(CASES))
    ap.add_argument("--skip-example", action="store_true", help="leave out Example 5.1's plans")
    ap.add_argument("--run", action="store_true", help="plan --run: check the route it recommends (issue 42)")
    ap.add_argument("--cache", default=os.path.join(ROOT, "out", "planner_cache.json"),
                    help="measured configurations of this binary (resume an interrupted check); '' for none")
    args = ap.parse_args(argv)
    tmp = tempfile.mkdtemp(prefix="tresca-plan-")
    atexit.register(shutil.rmtree, tmp, True)  # the runs' files are intermediate
    version = binary_version()
    cache = Cache(args.cache if not args.quick else "", version)
    hs = Harness(out=os.path.join(out_dir(), "planner"))
    t0 = time.time()
    cost_note = ("Cost of a configuration = CPU time of `tresca-cr run SCENE --refine r --steps N [--solver ssn --tol "
                 "TOL] "
                 "-q` on the scene without `[exact]` (median of 3 under 2 s); planner cost = CPU time of `tresca-cr "
                 "plan "
                 "SCENE --target T` (all pilot runs; median of 3). Brute-force cheapest = the cheapest grid "
                 "configuration "
                 "whose true error meets the target. " if args.costs else
                 "Costs are not measured here: `make bench` runs `verification/planner.py --costs`. ")
    md = ["<!-- generated by verification/planner.py -->", "# The planner against the truth (issue 15)", "",
          f"Generated by `.venv/bin/python verification/planner.py{' --quick' if args.quick else ''}"
          f"{' --costs' if args.costs else ''}{' --run' if args.run else ''}"
          f"{' --cases ' + ' '.join(args.cases) if args.cases != list(CASES) else ''}`. "
          f"Machine: {os.uname().nodename}, {os.cpu_count()} cores. Binary: "
          f"{version}.", "",
          "True error = `run.max_errors.energy` of `tresca-cr run SCENE --refine r --steps N [--solver ssn --tol TOL] "
          "--json F` on the scene with `[exact]`; the plan = `plan.plan` of `tresca-cr plan SCENE --target T --json "
          "F`. "
          + cost_note, ""]
    rows = []
    for name in args.cases:
        print(f"{name}:", flush=True)
        grid, sweep, steps = sweep_case(name, CASES[name], tmp, args.quick, cache, args.costs, args.run)
        n0 = len(hs.results)
        requirements(hs, name, sweep, f"verification/planner.py --cases {name}")
        md += case_md(name, grid, sweep, steps, args.costs)
        md += [f"* **{r.id}** {'PASS' if r.passed else 'FAIL'}: {r.statement} — {r.measured}" for r in hs.results[n0:]]
        md.append("")
        rows += csv_rows(sweep) if args.costs else []
    if not args.skip_example:
        md += ["## Example 5.1 (the paper's scene, no exact solution)", "", example51(tmp, args.quick, args.costs)]
    md += ["", f"Total time of this check: {time.time() - t0:.0f} s."]
    with open(args.md, "w", encoding="utf-8") as f:
        f.write("\n".join(md) + "\n")
    if args.costs and not args.quick:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]) if rows else ["case"])
            w.writeheader()
            w.writerows(rows)
    if args.json:
        hs.dump(args.json)
    return 1 if hs.failed else 0

"""The Markdown and CSV of verification/planner.py (:mod:`tresca_py.verify.planner`): one section per case —
the sweep (targets, the plan chosen, predicted and true errors, work against the cheapest grid configuration),
the grid, and with --costs the CPU benchmark rows.

Work units (the cost of PL5, deterministic): W(n, N) = n^1.5 + N·n·ln n for a run of n unknowns and N steps,
the planner's cost model (set-up ∝ n^1.5 at its upper exponent, a step ∝ n ln n: src/plan/model.rs) with equal
constants, as measured on mms_front at refine 6 (set-up 4.6 s ≈ 1.8e-8·n^1.5, a step 0.095 s ≈ 1.8e-8·n ln n,
n = 394,240: the grid of reference/planner_issue42.md); an adaptive route costs the sum over its levels.
"""
import math
import statistics


# issue 42 item 5: the cost model's predicted wall of a plan from this many seconds on is to be within 1.5× of
# its measured wall (a benchmark row of `make bench`, no pass/fail)
SMALL_PLAN = 0.3


def work(n, steps):
    """W(n, N) (module doc)."""
    return n ** 1.5 + steps * n * math.log(n)


def cost_rows(sweep):
    """The --costs benchmark rows of one case (no pass/fail): the plan's CPU against the cheapest grid
    configuration meeting the target, and the planner's CPU against the plan's at the two finest levels."""
    planned = [s for s in sweep if not s["refused"]]
    ratios = [s["cpu"] / s["cheapest"]["cpu"] for s in planned if s["cheapest"]]
    uniform = [s for s in planned if s["route"] == "uniform"]
    levels = sorted({s["refine"] for s in uniform})[-2:]
    shares = [s["planner_cpu"] / s["cpu"] for s in uniform if s["refine"] in levels]
    nan = float("nan")
    walls = [s["pred_wall"] / s["wall"] for s in uniform if s["pred_wall"] >= SMALL_PLAN]
    return [f"predicted wall / measured wall of the plans predicted at ≥ {SMALL_PLAN} s: "
            f"{min(walls, default=nan):.2f}–{max(walls, default=nan):.2f} over {len(walls)} plans (issue 42: within "
            "1.5×; measured wall: median of 3 runs of the plan on the scene without [exact])",
            f"plan CPU / cheapest grid CPU: max {max(ratios, default=nan):.2f}, median "
            f"{statistics.median(ratios) if ratios else nan:.2f} over {len(ratios)} targets (issue 15: within 2x)",
            f"planner CPU / plan CPU at refine {levels}: max {max(shares, default=nan):.3f} over {len(shares)} targets "
            "(issue 15: < 0.2; issue 32: <= 0.05)"]


def case_md(name, grid, sweep, steps, costs):
    """The Markdown section of one case: the sweep, the grid, and with ``costs`` the benchmark rows."""
    md = [f"## {name}", ""]
    head = "| target | plan r | N | tol | predicted error | true error | true/target | work / cheapest (r, N) |"
    if costs:
        head += (" plan CPU | predicted wall | planner CPU | planner/plan | cheapest-CPU r, N | its error | its CPU | "
                 "plan/cheapest |")
    ncols = head.count("|") - 1
    md += [head, "|" + "---|" * ncols]
    for s in sweep:
        if s["refused"]:
            md.append(f"| {s['target']:.3e} | refused |" + " |" * (ncols - 2))
            continue
        cw = s["cheapest_work"]
        row = (f"| {s['target']:.3e} | {s['refine']} | {s['steps']} | {s['tol']:g} | {s['pred_error']:.3e} | "
               f"{s['error']:.3e} | {s['error'] / s['target']:.3f} | {s['work'] / cw['work']:.2f} "
               f"({cw['refine']}, {cw['steps']}) |")
        if costs:
            ch = s["cheapest"]
            chs = (f"{ch['refine']}, {ch['steps']} | {ch['error']:.3e} | {ch['cpu']:.3f} s") if ch else "– | – | –"
            ratio = f"{s['cpu'] / ch['cpu']:.2f}" if ch else "–"
            row += (f" {s['cpu']:.3f} s | {s['pred_wall']:.3f} s | {s['planner_cpu']:.3f} s | "
                    f"{s['planner_cpu'] / s['cpu']:.3f} | {chs} | {ratio} |")
        md.append(row)
    what = "true energy error / CPU seconds" if costs else "true energy error"
    md += ["", f"Plan command: `tresca-cr plan verification/cases/{name}.toml --target T`. Grid ({what}; steps as "
           "columns; – : not run, no question of the check needed it: `tresca_py/verify/planner_grid.py`):", "",
           "| r | " + " | ".join(f"N = {n}" for n in steps) + " |", "|" + "---|" * (len(steps) + 1)]
    cell = {(g["refine"], g["steps"]): g for g in grid}
    for r in sorted({g["refine"] for g in grid}):
        cells = [cell.get((r, n)) for n in steps]
        md.append(f"| {r} | " + " | ".join("–" if c is None else f"{c['error']:.3e}" +
                                          (f" / {c['cpu']:.3f}" if costs else "") for c in cells) + " |")
    md.append("")
    if costs:
        md += ["Benchmark rows (CPU times; not requirements):", ""] + [f"* {line}" for line in cost_rows(sweep)] + [""]
    return md


def csv_rows(sweep):
    rows = []
    for s in sweep:
        if s["refused"]:
            continue
        ch = s["cheapest"]
        rows.append(dict(case=s["case"], target=s["target"], refine=s["refine"], steps=s["steps"], tol=s["tol"],
                         pred_error=s["pred_error"], true_error=s["error"], cpu=s["cpu"], wall=s["wall"],
                         pred_wall=s["pred_wall"], planner_cpu=s["planner_cpu"],
                         cheapest_refine=ch["refine"] if ch else "", cheapest_steps=ch["steps"] if ch else "",
                         cheapest_cpu=ch["cpu"] if ch else ""))
    return rows



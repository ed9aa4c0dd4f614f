"""The adaptive study of ``make verify`` (issue 33): ``tresca-cr adapt`` on the manufactured cases (the
L-shape ``mms_lshape`` with its corner singularity among them), Example 5.1 and the physical L-shape, each
against uniform refinement (``--theta 1``) in the same study.

Rates are slopes in DOF: a level's error e ∝ DOF^(−r), r the least-squares slope of log e against log DOF
over a stated range of levels (:func:`tresca_py.common.orders` on the DOF, negated). The project's
asymptotic-range check applies: at least four levels, and the fit AND the last two successive rates lie in
the band. Adaptive levels grow by only ×1.3 in DOF (θ = 0.5), and Dörfler's greedy marking puts a level's
error ±5 % off the trend, so successive rates are taken over windows of three levels (DOF ×2.2–2.5):
±5 % at both ends of a ×2.3 window moves its rate by ln(1.05²)/ln 2.3 = 0.12, the window band; the fit's
band is 0.05 (the project's ±0.1 on orders in h, h ∝ DOF^(−1/2)). Uniform levels (every triangle bisected
once, DOF ×2) are taken in pairs (DOF ×4, h halved) with the band 0.05.

Errors without an exact solution are distances to the reference of ``--reference G`` (the finest level's
mesh refined to bisection generation ≥ G; src/adapt/reference.rs). Only levels with at most the DOF of the
uniform generation G − 4 enter a rate: the reference then has ≥ 16 times their DOF, its own error is ≤
16^(−0.43) ≈ 0.3 of theirs, and |||u − u_l|||² ≈ |||u_ref − u_l|||² + |||u − u_ref|||² makes the distance
low by ≤ 5 % at the finest level used and less at the coarser ones: a rate bias ≤ ln(1/0.95)/ln 50 ≈ 0.013
over the ranges used (DOF ×50 and more). On Example 5.1 the fit starts at level 3: levels 0–2 (8–19
triangles) are left out as too coarse to be asymptotic; the window check then tests the range.
"""
import csv
import math
import os
import re
import time

from tresca_py import adapt_plot, bisection
from tresca_py.common import BIN, case, cmdline, orders, run, short_path
from tresca_py.mesh import build_mesh
from tresca_py.scene import load_scene
from tresca_py.verify import adapted_reimpl
from tresca_py.verify.studytools import req

SUB = "adaptive"   # the study's files: out/verify/reference/adaptive/ → reference/adaptive/
STUDY_MD = "reference/adaptive/study.md"
FIT_BAND, WINDOW_BAND, PAIR_BAND = 0.05, 0.12, 0.05
# an effectivity that drifts means η and the error converge at different rates: allowed, the fit band
# over the levels' DOF range, times the ±5 % per-level scatter at both ends
SCATTER = 1.05 ** 2
# CSV min angles carry 4 decimals
ANGLE_ROUNDING = 5e-5
# issue 42: the error estimate's effectivity E/error at every level past the first four (src/adapt/estimate.rs:
# TRUSTED_FROM = 4, the levels before it calibrate on one to three increments)
ESTIMATE_BAND, TRUSTED_FROM = (0.8, 1.25), 4


def staged(hs, name):
    """Where ``reference/adaptive/NAME`` is staged (its folder created)."""
    path = hs.path(os.path.join(SUB, name))
    os.makedirs(os.path.dirname(path), exist_ok=True)
    return path


def adapt(hs, scene, name, levels, theta, reference=None, out=None, gmsh=False):
    """Run ``tresca-cr adapt`` with its CSV staged as reference/adaptive/NAME.csv (``out``: the level files
    there, with ``gmsh`` their meshes as Gmsh too); returns (rows, command). Rows: numbers as floats, empty
    fields None."""
    path = staged(hs, f"{name}.csv")
    cmd = [BIN, "adapt", scene, "--levels", str(levels), "--theta", str(theta), "--csv", path, "--force"]
    if reference is not None:
        cmd += ["--reference", str(reference)]
    if out is not None:
        cmd += ["--out", out] + (["--gmsh"] if gmsh else [])
    run(cmd)
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k, v in r.items():
            r[k] = v if k == "error_kind" else (None if v == "" else float(v))
    return rows, cmdline(cmd).replace(short_path(hs.staged) + "/", "reference/")


def rate(rows, col, levels):
    """(fitted rate, successive rates) of ``col`` against DOF over the rows of ``levels`` (in order)."""
    sel = [rows[k] for k in levels]
    succ, fit = orders([r["unknowns"] for r in sel], [r[col] for r in sel])
    return -fit, [-s for s in succ]


def rate_check(rows, col, fit_levels, window_levels, r0, window_band):
    """The project's asymptotic-range check on rates: ≥ 4 levels, the fit over ``fit_levels`` within
    FIT_BAND of ``r0`` and the last two successive rates over ``window_levels`` within ``window_band``.
    Returns (passed, fit, windows, text)."""
    fit, _ = rate(rows, col, fit_levels)
    _, win = rate(rows, col, window_levels)
    ok = (len(fit_levels) >= 4 and len(window_levels) >= 4 and abs(fit - r0) <= FIT_BAND
          and all(abs(w - r0) <= window_band for w in win[-2:]))
    text = (f"DOF^(−{fit:.3f}) fitted over levels {fit_levels[0]}–{fit_levels[-1]} "
            f"({rows[fit_levels[0]]['unknowns']:.0f}–{rows[fit_levels[-1]]['unknowns']:.0f} unknowns); "
            f"rates over levels {', '.join(str(k) for k in window_levels)}: {', '.join(f'{w:.3f}' for w in win)}")
    return ok, fit, win, text


def effectivity_check(rows):
    """Reliability η ≥ |||e||| at every level and max/min ≤ SCATTER·(DOF_last/DOF_0)^FIT_BAND.
    Returns (passed, text)."""
    eff = [r["effectivity"] for r in rows]
    lo, hi = min(eff), max(eff)
    bound = SCATTER * (rows[-1]["unknowns"] / rows[0]["unknowns"]) ** FIT_BAND
    ok = len(rows) >= 10 and lo >= 1.0 and hi / lo <= bound
    return ok, (f"η/error {lo:.2f}–{hi:.2f} over {len(rows)} levels ({rows[0]['unknowns']:.0f}–"
                f"{rows[-1]['unknowns']:.0f} unknowns): max/min {hi / lo:.3f} ≤ {bound:.3f}, min ≥ 1")


def estimate_check(hs, name, rows, col, cmd):
    """A7: the error estimate's effectivity E / error (``col``: the true error or the reference distance) in
    ESTIMATE_BAND at every level from TRUSTED_FROM on."""
    eff = [(int(r["level"]), r["estimate"] / r[col]) for r in rows[TRUSTED_FROM:]
           if r["estimate"] is not None and r[col]]
    lo, hi = min(e for _, e in eff), max(e for _, e in eff)
    ok = len(eff) == len(rows) - TRUSTED_FROM >= 10 and ESTIMATE_BAND[0] <= lo and hi <= ESTIMATE_BAND[1]
    label = "true error" if col == "error" else "reference distance"
    req(hs, f"A7-estimate-{name}", f"on `{name}` the adaptive error estimate's effectivity E / {label} shall lie in "
        f"[{ESTIMATE_BAND[0]}, {ESTIMATE_BAND[1]}] at every level past the first {TRUSTED_FROM} (issue 42)", ok,
        f"E/error {lo:.3f}–{hi:.3f} over levels {eff[0][0]}–{eff[-1][0]} "
        f"({rows[TRUSTED_FROM]['unknowns']:.0f}–{rows[-1]['unknowns']:.0f} unknowns)", cmd, STUDY_MD)


def dof_for(rows, col, target):
    """DOF at which ``col`` first falls to ``target`` (log-log interpolation between levels); None when the
    levels do not reach it."""
    for a, b in zip(rows, rows[1:], strict=False):
        if a[col] is not None and b[col] is not None and b[col] <= target:
            if a[col] <= target:
                return a["unknowns"]
            s = math.log(target / a[col]) / math.log(b[col] / a[col])
            return math.exp(math.log(a["unknowns"]) + s * math.log(b["unknowns"] / a["unknowns"]))
    return None


def manufactured(hs, name, levels):
    """A1 (effectivity) and A2 (rate against the true error) on one manufactured case; the uniform route
    for the plot. Levels 9.. for the fit, windows from level 4 (tests/adapt.rs uses the same ranges)."""
    rows, cmd = adapt(hs, case(name), f"{name}_adaptive", levels, 0.5)
    uni, _ = adapt(hs, case(name), f"{name}_uniform", 8, 1)
    ok, text = effectivity_check(rows)
    req(hs, f"A1-effectivity-{name}", f"on `{name}` the indicator's effectivity η/|||u − u_h||| shall stay ≥ 1 "
        f"and within a bounded range over {levels} adapted levels", ok, text, cmd, STUDY_MD)
    ok, _, _, text = rate_check(rows, "error", list(range(9, levels)), list(range(4, levels, 3)), 0.5,
                                WINDOW_BAND)
    req(hs, f"A2-rate-{name}", f"on `{name}` the adaptive true error shall decay like DOF^(−1/2) (± {FIT_BAND} "
        f"fit, ± {WINDOW_BAND} over 3-level windows)", ok, text, cmd, STUDY_MD)
    return rows, uni


def coarse_enough(rows, uniform, generation):
    """The levels of ``rows`` with at most the DOF of uniform level ``generation`` (:data:`__doc__`)."""
    cap = uniform[generation]["unknowns"]
    return [k for k, r in enumerate(rows) if r["unknowns"] <= cap and r["vs_reference"] is not None]


def example_5_1(hs, levels, reference, out):
    """A3: Example 5.1 against the reference, adaptive rate 1/2 where uniform gives 0.43 (issue 33: the
    observed order 0.85–0.87 in h), both in this study."""
    scene = case("paper_example_5_1")
    rows, cmd = adapt(hs, scene, "example_5_1_adaptive", levels, 0.5, reference, out)
    uni, cmd_u = adapt(hs, scene, "example_5_1_uniform", reference - 3, 1, reference)
    keep = coarse_enough(rows, uni, reference - 4)
    windows = keep[-1::-3][:5][::-1]   # five levels three apart, ending at the finest kept
    ok_a, fit_a, _, text_a = rate_check(rows, "vs_reference", keep[3:], windows, 0.5, WINDOW_BAND)
    pairs = list(range(reference - 4, -1, -2))[::-1]
    ok_u, fit_u, _, text_u = rate_check(uni, "vs_reference", list(range(reference - 3)), pairs, 0.43, PAIR_BAND)
    ok = ok_a and ok_u and fit_a > fit_u
    req(hs, "A3-example-5-1", f"on Example 5.1 (errors against the generation-{reference} reference) the adaptive "
        f"error shall decay like DOF^(−1/2) ± {FIT_BAND} (windows ± {WINDOW_BAND}) where uniform refinement "
        f"gives DOF^(−0.43) ± {PAIR_BAND}, measured in the same study, adaptive faster",
        ok, f"adaptive {text_a}; uniform {text_u}", f"{cmd}; {cmd_u}", STUDY_MD)
    return rows, uni


def ratio_trend(rows, uni, col):
    """Per uniform level k ≥ 1: (k, DOF_uniform / DOF_adaptive at its accuracy) where the adaptive levels
    reach it."""
    return [(k, uni[k]["unknowns"] / d) for k in range(1, len(uni))
            if (d := dof_for(rows, col, uni[k][col])) is not None]


def lshape_mms(hs, levels, uniform_levels, out):
    """A1, A2 and A4 on mms_lshape (true errors): effectivity, adaptive DOF^(−1/2), and the adaptive DOF for
    the uniform finest level's accuracy ≤ 1/10 of its DOF. Reported beside A4: the uniform route's rates over
    pairs of levels (λ/2 = 0.272 asymptotically) and, when the bar is missed, the uniform DOF at which the
    ratio would reach 10 if it kept growing like DOF^(1 − r_u/r_a) (r_u the last pair's rate, r_a the
    adaptive fit: e_u ∝ DOF^(−r_u) and DOF_a ∝ e^(−1/r_a))."""
    scene = case("mms_lshape")
    rows, cmd = adapt(hs, scene, "mms_lshape_adaptive", levels, 0.5, out=out)
    uni, cmd_u = adapt(hs, scene, "mms_lshape_uniform", uniform_levels, 1)
    ok, text = effectivity_check(rows)
    req(hs, "A1-effectivity-mms_lshape", "on `mms_lshape` the indicator's effectivity η/|||u − u_h||| shall stay ≥ 1 "
        f"and within a bounded range over {levels} adapted levels", ok, text, cmd, STUDY_MD)
    ok, r_a, _, text = rate_check(rows, "error", list(range(9, levels)), list(range(4, levels, 3)), 0.5,
                                  WINDOW_BAND)
    req(hs, "A2-rate-mms_lshape", f"on `mms_lshape` the adaptive true error shall decay like DOF^(−1/2) (± {FIT_BAND} "
        f"fit, ± {WINDOW_BAND} over 3-level windows)", ok, text, cmd, STUDY_MD)
    target, d_u = uni[-1]["error"], uni[-1]["unknowns"]
    d_a = dof_for(rows, "error", target)
    ok = d_a is not None and d_a <= d_u / 10
    pairs = list(range(len(uni) - 1, -1, -2))[::-1]
    _, r_pairs = rate(uni, "error", pairs)
    got = "not reached" if d_a is None else f"≈ {d_a:.0f} unknowns, ratio {d_u / d_a:.1f}"
    if d_a is not None and not ok:
        d10 = d_u * (10 * d_a / d_u) ** (1 / (1 - r_pairs[-1] / r_a))
        got += f"; at this trend (r_u = {r_pairs[-1]:.3f}, r_a = {r_a:.3f}) 10 at ≈ {d10:.2g} uniform unknowns"
    req(hs, "A4-lshape-dof", "on the manufactured L-shape (`mms_lshape`: the re-entrant corner's r^0.5445 "
        "singularity, true errors) the adaptive route shall reach the uniform route's finest accuracy with at "
        "most a tenth of its unknowns (issue 33's bar)", ok,
        f"uniform level {len(uni) - 1}: {target:.3e} with {d_u:.0f} unknowns; adaptive: {got} (ratio at uniform "
        f"levels {', '.join(f'{k}: {r:.1f}' for k, r in ratio_trend(rows, uni, 'error'))}; uniform rates over "
        f"level pairs {', '.join(f'{r:.3f}' for r in r_pairs)}, λ/2 = 0.272 asymptotically)",
        f"{cmd}; {cmd_u}", STUDY_MD)
    return rows, uni


def lshape(hs, levels, uniform_levels, reference, out):
    """The physical L-shape (`lshape_adapt`, errors against a reference): reported, no bar (A4 is on
    mms_lshape, whose errors are true ones); its runs serve A5, A6 and the pictures. Returns (rows, uniform
    rows, the ratio text)."""
    scene = case("lshape_adapt")
    rows, cmd = adapt(hs, scene, "lshape_adaptive", levels, 0.5, reference, out, gmsh=True)
    uni, cmd_u = adapt(hs, scene, "lshape_uniform", uniform_levels, 1, reference)
    target = uni[-1]["vs_reference"]
    d_u, d_a = uni[-1]["unknowns"], dof_for(rows, "vs_reference", target)
    got = "not reached" if d_a is None else f"≈ {d_a:.0f} unknowns, ratio {d_u / d_a:.1f}"
    text = (f"`lshape_adapt` (reported, no bar; against the generation-{reference} reference): uniform level "
            f"{len(uni) - 1}: {target:.3e} with {d_u:.0f} unknowns; adaptive: {got} (ratio at uniform levels "
            f"{', '.join(f'{k}: {r:.1f}' for k, r in ratio_trend(rows, uni, 'vs_reference')[:-1])}). "
            f"Commands: `{cmd}`; `{cmd_u}`")
    return rows, uni, text


def min_angle(hs, routes):
    """A5: every level's minimum angle at or above NVB's bound for its initial mesh (:mod:`tresca_py.bisection`),
    one result per scene (``routes``: scene name → list of (route name, rows))."""
    for name, runs in routes.items():
        m = build_mesh(load_scene(case(name)))
        bound = bisection.descendant_bound(m.points, m.triangles)
        kind = "Gmsh" if "file" in load_scene(case(name)).mesh else "structured"
        parts, ok = [], True
        for route, rows in runs:
            angles = [r["min_angle_deg"] for r in rows]
            ok = ok and min(angles) >= bound - ANGLE_ROUNDING
            parts.append(f"{route} {len(rows)} levels: {min(angles):.4f}–{max(angles):.4f}°")
        req(hs, f"A5-min-angle-{name}", f"on `{name}` ({kind} mesh) every adapted level's minimum angle shall stay at "
            "or above newest-vertex bisection's bound for the initial mesh (its descendants' similarity classes)",
            ok, f"bound {bound:.4f}°; " + "; ".join(parts), "verification/run_all.py --only adaptive",
            STUDY_MD)


def reimplementations(hs, out, k):
    """A6: every level's Gmsh file holds its mesh; on level k's, scikit-fem and dolfinx agree with the Rust run
    (and the adapt run's own level file with it) to ≤ 1e-8, the cross-check's bar."""
    n = adapted_reimpl.level_count(out)
    tris = [adapted_reimpl.gmsh_matches_level(out, j) for j in range(n)]
    pairs = adapted_reimpl.agreement(case("lshape_adapt"), out, k)
    ok = all(adapted_reimpl.worst(c) <= 1e-8 and c["flags"] == 0 for c in pairs.values())
    text = (f"{n} level_<k>.msh files = their level's mesh ({tris[0]}–{tris[-1]} triangles); level {k} "
            f"({tris[k]} triangles): " + "; ".join(
                f"{p} max {adapted_reimpl.worst(c):.1e} (du {c['du']:.1e}, dσ {c['dsig']:.1e}), {c['flags']} flags"
                for p, c in pairs.items()))
    req(hs, "A6-adapted-mesh", "on an adapted L-shape mesh written by `adapt --gmsh`, the scikit-fem and dolfinx "
        "re-implementations shall agree with the Rust solver to ≤ 1e-8 (DOF vectors, energies, σ_τ, stick/slip)",
        ok, text, f"tresca-cr adapt verification/cases/lshape_adapt.toml … --out DIR --gmsh; scripts/"
        f"{{skfem,dolfinx}}_solve.py DIR/level_{k}.toml; scripts/compare.py --tol 1e-8", STUDY_MD)


def figures(hs, pairs, mesh_dirs):
    """Error against DOF per case (adaptive and uniform) and the meshes of the levels (where the refinement
    goes), staged in reference/adaptive/."""
    for name, title in pairs:
        adapt_plot.rates_picture(staged(hs, f"{name}_adaptive.csv"), staged(hs, f"{name}_uniform.csv"),
                                 staged(hs, f"{name}_rates.png"), title)
    for name, (directory, levels) in mesh_dirs.items():
        for k in levels:
            adapt_plot.mesh_picture(os.path.join(directory, f"level_{k}.h5"), staged(hs, f"{name}/mesh_{k}.png"),
                                    f"{name} level {k}")


def table(name, rows, col):
    """One Markdown table of a route's levels."""
    label = "true error" if col == "error" else "vs reference"
    lines = [f"### {name}", "", f"| level | unknowns | estimator η | {label} | η / error | estimate E | E / error "
             "| min angle ° |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        e = "–" if r[col] is None else f"{r[col]:.3e}"
        eff = "–" if r["effectivity"] is None else f"{r['effectivity']:.2f}"
        est = r.get("estimate")
        ee = "–" if est is None or not r[col] else f"{est / r[col]:.3f}"
        lines.append(f"| {r['level']:.0f} | {r['unknowns']:.0f} | {r['estimator']:.3e} | {e} | {eff} | "
                     f"{'–' if est is None else f'{est:.3e}'} | {ee} | {r['min_angle_deg']:.2f} |")
    return "\n".join(lines) + "\n"


def study(hs):
    """The study (about 3 min on 2 cores): A1, A2 per manufactured case, A3, A4 (mms_lshape; the physical
    L-shape reported), A5 per scene, A6; its tables in reference/adaptive/study.md, its figures beside
    them."""
    t0 = time.perf_counter()
    work = os.path.join(hs.out, SUB)
    ex51_dir, lsh_dir = os.path.join(work, "example_5_1"), os.path.join(work, "lshape")
    mms_dir = os.path.join(work, "mms_lshape")
    routes, md = {}, []
    for name in ("mms_elastic", "mms_stick_to_slip"):
        a, u = manufactured(hs, name, 17)
        routes[name] = [("adaptive", a), ("uniform", u)]
        md += [table(f"{name}, adaptive (θ = 0.5)", a, "error"), table(f"{name}, uniform", u, "error")]
    a, u = example_5_1(hs, 16, 12, ex51_dir)
    estimate_check(hs, "paper_example_5_1", a, "vs_reference", "tresca-cr adapt "
                   "verification/cases/paper_example_5_1.toml --levels 16 --theta 0.5 --reference 12 --csv …")
    routes["paper_example_5_1"] = [("adaptive", a), ("uniform", u)]
    md += [table("Example 5.1, adaptive (reference generation 12)", a, "vs_reference"),
           table("Example 5.1, uniform", u, "vs_reference")]
    a, u = lshape_mms(hs, 24, 13, mms_dir)
    estimate_check(hs, "mms_lshape", a, "error", "tresca-cr adapt verification/cases/mms_lshape.toml --levels 24 "
                   "--theta 0.5 --csv …")
    routes["mms_lshape"] = [("adaptive", a), ("uniform", u)]
    a, cmd = adapt(hs, case("mms_data_front"), "mms_data_front_adaptive", 20, 0.5)
    estimate_check(hs, "mms_data_front", a, "error", cmd)
    md.append(table("mms_data_front, adaptive (θ = 0.5)", a, "error"))
    md += [table("mms_lshape, adaptive (θ = 0.5)", a, "error"), table("mms_lshape, uniform", u, "error")]
    a, u, physical = lshape(hs, 13, 7, 10, lsh_dir)
    routes["lshape_adapt"] = [("adaptive", a), ("uniform", u)]
    md += [table("L-shape, adaptive (reference generation 10)", a, "vs_reference"),
           table("L-shape, uniform", u, "vs_reference"), physical + "\n"]
    min_angle(hs, routes)
    reimplementations(hs, lsh_dir, 6)
    figures(hs, [("mms_elastic", "mms_elastic: true error"), ("mms_stick_to_slip", "mms_stick_to_slip: true error"),
                 ("example_5_1", "Example 5.1: against the reference"), ("lshape", "L-shape: against the reference"),
                 ("mms_lshape", "mms_lshape: true error")],
            {"example_5_1": (ex51_dir, (0, 5, 10, 15)), "lshape": (lsh_dir, range(13)),
             "mms_lshape": (mms_dir, (0, 8, 16, 23))})
    results = [r for r in hs.results if re.match(r"A\d-", r.id)]
    head = ["<!-- generated by verification/run_all.py --only adaptive -->", "# Adaptive study (make verify)", "",
            f"`.venv/bin/python verification/run_all.py --only adaptive`: {time.perf_counter() - t0:.0f} s on "
            f"{os.cpu_count()} cores (reported, not required). Errors: energy norm, max over the time nodes; "
            "rates are slopes against DOF (tresca_py/verify/adaptive.py states the ranges and bands).", "",
            "| requirement | result | measured | command |", "|---|---|---|---|"]
    head += [f"| {r.id} | {'PASS' if r.passed else 'FAIL'} | {r.measured} | `{r.command}` |" for r in results]
    with open(staged(hs, "study.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(head) + "\n\n" + "\n".join(md))

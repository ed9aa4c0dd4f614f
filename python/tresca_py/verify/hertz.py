"""HZ1–HZ4 of ``make verify``: the Hertz line contact (issue 40 item 3; tresca_py.hertz). A plane-strain elastic
cylinder (R = 1, E = 1, ν = 0.3) on a rigid plane, frictionless unilateral contact, symmetry part on x = 0,
floating (no Dirichlet part; the cut through the centre carries the traction P/(2R)), two loads a/R = 0.1 and
0.05, five mesh levels each (h halves everywhere; --quick too: HZ1 needs four errors against the finest, and the
whole study takes about two minutes).

The model: the scheme solves small-deformation Signorini with the gap and the pressure along the undeformed
normal n = (x, y − R)/R, tilted by θ = x/R from Hertz's vertical. The tilt makes the frictionless traction carry
a shear p x/R, and u·n pick up u_x x/R; by Johnson's (2.25) each changes the surface slope by
(1 − 2ν)/(1 − ν) · p(x) x/(R E*), relative to Hertz's gap slope x/R at most κ p₀/E* = κ a/(2R) with
κ = (1 − 2ν)/(1 − ν). So the half-space model's own error is first order in a/R here, proportional to κ (it
vanishes for ν = ½); the circle's x⁴ term and the finite body add O((a/R)² log(R/a)); a ∝ curvature^(−1/2) moves
by about half of the curvature's change.

* HZ1 discretisation: the cut's approach δ and a_moment per level against the finest level converge with fitted
  order 2 ± 0.5 (a functional of a solution whose energy-norm error is O(h), doubled by duality) over 4 errors, the
  last successive order ≥ 1 (still in the asymptotic range at the finest levels); the peak p₀_h (one edge's
  pressure, a pointwise value on non-nested meshes: no order) changes by ≤ 1/4 of the model bound at the finest level.
* HZ2 at the finest level |a_moment/a − 1| and |p₀_h/p₀ − 1| ≤ κ a/(2R), the profile's L² error ≤ κ a/R (a shift
  ε of the zone's end costs the √-profile about 2ε in L²); at every level the P measured on Γ_C equals the given
  P to EQUILIBRIUM (the floating body's vertical balance, solved exactly up to rounding).
* HZ3 the deviations of a and p₀ shrink with a/R at order 1 ± 0.3 between the two loads (first order, see above;
  the band leaves room for the (a/R)² log terms), and drop to below half at ν = 0.49 (κ 0.57 → 0.04), one level
  below the finest. The profile's errors are reported, not held to an order: a zone end off by ε a costs the
  √-profile ~ε √log(1/ε) in L² and √(2ε) in L∞ near the end, not ε.
* HZ4 the polygon's error (the run with the circle's gap minus the polygon's) in a/a(P) and p₀/p₀(P) is at every
  level ≤ h²/(8a²) (the sagitta h²/(8R) against the gap a²/(2R) in the zone, a moving by half of it) and
  ≤ 1/4 of the level's a_moment discretisation error.
"""
import math
import os

from tresca_py.common import cmdline, orders
from tresca_py.hertz.levels import LOADS, run_level, variant
from tresca_py.verify.harness import out_dir
from tresca_py.verify.studytools import req

COMMAND = ".venv/bin/python verification/run_all.py --only hertz"
REFERENCE = "reference/hertz.md"
#: the model's first-order constant κ = (1 − 2ν)/(1 − ν) for the study's ν = 0.3
KAPPA = (1 - 2 * 0.3) / (1 - 0.3)
#: the orders of HZ1 (2 ± 0.5 fitted, last successive ≥ 1) and of HZ3 (1 ± 0.3 in a/R)
ORDER, ORDER_BAND, ORDER_MIN = 2.0, 0.5, 1.0
MODEL_ORDER, MODEL_BAND = 1.0, 0.3
NU_NEAR_HALF = 0.49
#: |P_h/P − 1| allowed: the contact forces balance the load exactly in the floating solve (rounding of sums of
#: O(10⁵) edge forces, ~1e-16 each, with the 1e-12 natural residual of the semismooth Newton solve)
EQUILIBRIUM = 1e-9


INTRO = """A plane-strain elastic cylinder (R = 1, E = 1, ν = 0.3) on a rigid plane, frictionless unilateral contact,
by symmetry a quarter disc: symmetry part on x = 0, no Dirichlet part (the body floats, held in y by the contact
alone), the cut y = R through the centre loaded by the traction (0, −P/(2R)), P = π E* a²/(4R) for a/R = 0.1 and
0.05. Scenes and meshes: `tresca_py.hertz` (`verification/cases/hertz_a10.toml`, `hertz_a05.toml` are level 0).
Each level is a new graded mesh (h halves everywhere, h ≈ a/4 · 2^−level in the zone |p| ≤ 2a) whose arc vertices
lie on the circle. Checked against Hertz from the P measured on Γ_C (= the given P: the vertical equilibrium):
a_moment = 2√(M₂/M₀) (Hertz: ∫p x² = a²∫p/4), a_edge (outermost pressed edge's end, within one edge), p₀_h (largest
edge pressure), the profile error against the exact edge means of p₀√(1 − x²/a²), L² (√(Σ|e|err²/a)/p₀) and L∞ (/p₀).
The profile's errors are dominated by the zone's end: an end off by ε a costs the √-profile about √(2ε) in L∞
(0.17 for ε = 0.015) and ε √log(1/ε) in L², so they settle at the model error's image, not at zero.

Model error. The scheme is small-deformation Signorini along the undeformed normal, tilted by θ = x/R from
Hertz's vertical: the frictionless traction carries a shear p x/R and u·n picks up u_x x/R, each changing the
surface slope by κ p(x) x/(R E*) with κ = (1 − 2ν)/(1 − ν) (Johnson, Contact Mechanics, (2.25)), at most κ a/(2R) of
Hertz's gap slope x/R: a first-order model error, proportional to κ (the ν table), plus O((a/R)² log(R/a)) from
the circle's x⁴ term and the finite body. Polygon error: the run with the circle's gap at every point (instead of
the polygon's own, which is off by at most the sagitta h²/(8R)) changes a/a(P) and p₀/p₀(P) by the column
"polygon error", bounded by h²/(8a²) and far below the discretisation error.
"""


def row(ld, k):
    """One level of load ``ld``: the table's row and the command."""
    c, dofs, cmd = run_level(os.path.join(out_dir(), "hertz"), ld, k)
    dev_am, dev_ae, dev_p0 = c.deviations()
    return dict(level=k, dofs=dofs, h=c.h_c, a_R=c.a / ld.case.R, h_a=c.h_c / c.a, P=c.P, delta=c.delta,
                a_moment=c.a_moment,
                p0_h=c.p0_h, dev_am=dev_am, dev_ae=dev_ae, dev_p0=dev_p0, linf=c.linf, l2=c.l2,
                edges=c.edges), cmd


def discretisation(rows, key):
    """(errors |f_l − f_finest|/|f_finest| for l < finest, successive orders, fitted order) of quantity ``key``."""
    f = rows[-1][key]
    e = [abs(r[key] - f) / abs(f) for r in rows[:-1]]
    if min(e) == 0:                               # no order from an exact zero (a pointwise value can repeat)
        return e, [math.nan] * (len(e) - 1), math.nan
    succ, fit = orders([r["h"] for r in rows[:-1]], e)
    return e, succ, fit


def polygon(ld, rows):
    """Per level but the finest: max of the changes of a_moment/a − 1 and p₀_h/p₀ − 1 with the circle's gap."""
    circle = variant(ld, circle_gap=True)
    out = []
    for r in rows[:-1]:
        c, _ = row(circle, r["level"])
        out.append(max(abs(c["dev_am"] - r["dev_am"]), abs(c["dev_p0"] - r["dev_p0"])))
    return out


def table(ld, rows, poly, nus):
    given = f"P = {ld.case.P:.6e}" if ld.case.P is not None else f"δ = {ld.case.delta}"
    lines = [f"## {ld.name}: {given}, a/R = {rows[-1]['a_R']:.4f} at the finest level", "",
             "| level | DOF | h/a | P | δ | a_moment/a − 1 | a_edge/a − 1 | p₀_h/p₀ − 1 | profile L² | profile L∞ | "
             "pressed edges | polygon error | h²/(8a²) |", "|" + "---|" * 13]
    for i, r in enumerate(rows):
        p = f"{poly[i]:.2e}" if i < len(poly) else "-"
        lines.append(f"| {r['level']} | {r['dofs']} | {r['h_a']:.4f} | {r['P']:.6e} | {r['delta']:.6e} | "
                     f"{r['dev_am']:+.4e} | {r['dev_ae']:+.4e} | {r['dev_p0']:+.4e} | {r['l2']:.4e} | "
                     f"{r['linf']:.4e} | {r['edges']} | {p} | {r['h_a'] ** 2 / 8:.2e} |")
    lines += ["", "| quantity | discretisation error per level (vs finest) | successive orders | fitted order |",
              "|---|---|---|---|"]
    for key in ("delta", "a_moment", "p0_h"):
        e, succ, fit = discretisation(rows, key)
        lines.append(f"| {key} | {', '.join(f'{v:.2e}' for v in e)} | {', '.join(f'{s:.2f}' for s in succ)} | "
                     f"{fit:.2f} |")
    lines += ["", f"Model error against ν at level {nus[0][1]['level']}:", "",
              "| ν | κ | a/R | a_moment/a − 1 | p₀_h/p₀ − 1 | profile L² |", "|---|---|---|---|---|---|"]
    lines += [f"| {nu} | {(1 - 2 * nu) / (1 - nu):.3f} | {r['a_R']:.4f} | {r['dev_am']:+.4e} | {r['dev_p0']:+.4e} | "
              f"{r['l2']:.4e} |" for nu, r in nus]
    return "\n".join(lines) + "\n"


def hz1(ld, rows):
    """(passed, measured) of HZ1 for one load."""
    ok, out = True, []
    for key in ("delta", "a_moment"):
        e, succ, fit = discretisation(rows, key)
        ok &= len(e) >= 4 and abs(fit - ORDER) <= ORDER_BAND and succ[-1] >= ORDER_MIN
        out.append(f"{key} fit {fit:.2f}, successive {', '.join(f'{s:.2f}' for s in succ)}")
    bound = KAPPA * rows[-1]["a_R"] / 2
    e, _, _ = discretisation(rows, "p0_h")
    ok &= e[-1] <= bound / 4
    return ok, f"{ld.name}: " + "; ".join(out) + f"; p₀_h finest change {e[-1]:.1e} (≤ {bound / 4:.1e})"


def hz2(ld, rows):
    r = rows[-1]
    bound = KAPPA * r["a_R"] / 2
    balance = max(abs(q["P"] / ld.case.P - 1) for q in rows) if ld.case.P is not None else 0.0
    ok = abs(r["dev_am"]) <= bound and abs(r["dev_p0"]) <= bound and r["l2"] <= 2 * bound and balance <= EQUILIBRIUM
    return ok, (f"{ld.name} (a/R {r['a_R']:.4f}): a {r['dev_am']:+.2e}, p₀ {r['dev_p0']:+.2e} (≤ {bound:.2e}), "
                f"profile L² {r['l2']:.2e} (≤ {2 * bound:.2e}), max |P_h/P − 1| {balance:.1e} (≤ {EQUILIBRIUM:.0e})")


def hz3(all_rows, all_nus):
    r1, r2 = (rows[-1] for rows in all_rows)
    ratio = math.log(r1["a_R"] / r2["a_R"])
    m = {k: math.log(abs(r1[k]) / abs(r2[k])) / ratio for k in ("dev_am", "dev_p0")}
    ok = all(abs(v - MODEL_ORDER) <= MODEL_BAND for v in m.values())
    drop = [abs(nus[-1][1][k]) / abs(nus[0][1][k]) for nus in all_nus for k in ("dev_am", "dev_p0")]
    ok &= max(drop) < 0.5
    return ok, (", ".join(f"{k} {v:.2f}" for k, v in m.items()) + f" (a/R {r1['a_R']:.4f} → {r2['a_R']:.4f}); "
                f"at ν = {NU_NEAR_HALF} the deviations are {', '.join(f'{d:.2f}' for d in drop)} of ν = 0.3's")


def hz4(ld, rows, poly):
    e, _, _ = discretisation(rows, "a_moment")
    ok = all(p <= r["h_a"] ** 2 / 8 and p <= d / 4 for p, r, d in zip(poly, rows[:-1], e, strict=True))
    ratios = ", ".join(f"{p / d:.1e}" for p, d in zip(poly, e, strict=True))
    return ok, f"{ld.name}: polygon / discretisation error per level {ratios}"


def study(hs, quick=False):
    """Record HZ1–HZ4 and stage reference/hertz.md."""
    n = 5                                          # also with --quick (see the module doc)
    runs = []
    for ld in LOADS:
        rows = [row(ld, k) for k in range(n)]
        cmd = rows[-1][1]
        rows = [r for r, _ in rows]
        nus = [(0.3, rows[-2])] + [(nu, row(variant(ld, nu=nu), n - 2)[0]) for nu in (0.45, NU_NEAR_HALF)]
        runs.append((ld, rows, polygon(ld, rows), nus))
    md = "\n".join(table(*r) for r in runs)
    hs.write("hertz.md", f"<!-- generated by {COMMAND}; one level: {cmdline(cmd)} -->\n# Hertz line contact\n\n"
             + INTRO + f"\nReproduce: `{COMMAND}` (stages this file in out/verify/reference/).\n\n" + md)
    res = [hz1(ld, rows) for ld, rows, _, _ in runs]
    req(hs, "HZ1-hertz-discretisation", None, all(ok for ok, _ in res), "; ".join(m for _, m in res), COMMAND,
        REFERENCE)
    res = [hz2(ld, rows) for ld, rows, _, _ in runs]
    req(hs, "HZ2-hertz-formulas", None, all(ok for ok, _ in res), "; ".join(m for _, m in res), COMMAND, REFERENCE)
    ok, m = hz3([r[1] for r in runs], [r[3] for r in runs])
    req(hs, "HZ3-hertz-model-order", None, ok, m, COMMAND, REFERENCE)
    res = [hz4(ld, rows, poly) for ld, rows, poly, _ in runs]
    req(hs, "HZ4-hertz-polygon", None, all(ok for ok, _ in res), "; ".join(m for _, m in res), COMMAND, REFERENCE)

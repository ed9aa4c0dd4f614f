"""The compared quantities, from a code's raw result (the same definitions for every code).

Each solver reports, at the final time T: ‖u‖_H1 (``h1_norm``), its energy ½a(u,u) (``energy``; tresca-cr:
½a_h with the jump term), ∫_{Γ_C} σ_τ (``sigma_t_integral``: the consistent traction — the projected Nitsche
traction P, or tresca-cr's multiplier), u·τ at the three probe points (1/4, 1/2, 3/4 of Γ_C), u·τ at uniform
samples of Γ_C, and a stick flag at points of Γ_C (Nitsche: |σ_τ(u) − p δu_τ| < g_a at the contact quadrature
points; tresca-cr: the edge state). From them :func:`summarise` adds

* ``max_slip``  = max over the samples of |u·τ| (u_n is imposed, so u·τ is the slip relative to the foundation),
* ``stick_a``, ``stick_b`` = the first and the last stick↔slip transition along Γ_C (arc length from its
  start): the first and last zero of the piecewise-linear interpolant, through the points where each code
  evaluates its contact state, of ψ = η_h − |δu_τ| (δu_τ the last step's slip increment), i.e. the ends of
  the slip's support measured at the threshold η_h = (h/|Γ_C|)² max_{Γ_C} |δu_τ| (h² ∝ the L∞ accuracy of
  the order-1 codes; one law for every code: the Nitsche codes' stick zones carry a slip of the size of
  their error, ≈ 7e-6 next to mms_front's Γ_C/Γ_N corner for GetFEM P2 at 32 cells, above (h/|Γ_C|)³ max
  |δu_τ| ≈ 2e-6, so an h^{k+1} threshold for P2 placed spurious transitions there; (h/|Γ_C|)² gives 4e-5
  there, and 1.1e-5 for GetFEM P1 at 64 cells against its 6e-6). NaN where ψ has one sign (nothing or
  everything slips). Points within h of an end of Γ_C that lies on Γ_D are left out: there the slip vanishes
  because u = u_D, not because friction holds it, and the threshold set next to the junction has length
  ≈ η_h/|∂_s δu_τ| = O(h²) < h (Example 5.1, all slip: the P2 codes otherwise found a stick zone of that
  length at the clamped end of Γ_C, the order-1 codes none).
  Why not the flags themselves: halfway between two points whose flags differ jumps by the point spacing as
  h changes (a three-level Richardson estimate of such a sequence means nothing), and a flag, or the zero of
  the stick margin g_a − |σ_τ|, is ill-conditioned where the margin closes to high order: on the
  manufactured scenes it closes like the cube of the distance to the front, so on mms_rotated's stick zone
  [0, 0.2] it is at most (1/5)(0.2)³ = 1.6e-3 against g_a ≈ 0.2, below the finest P2 level's traction error,
  and a code may see no stick zone at all. With a threshold the location error is (η_h + ‖δu_τ − δu_τ,h‖_∞)
  ^{1/m} for a slip that grows like d^m from the front: order 2/m (m = 3 on the manufactured scenes).
"""
from __future__ import annotations

import math

import numpy as np

#: quantities compared between codes, in table order
QUANTITIES = ("h1_norm", "energy", "u_tau_1", "u_tau_2", "u_tau_3", "sigma_t_integral", "stick_a", "stick_b",
              "max_slip", "normal_force", "max_pressure")
#: quantities only the unilateral codes report (NaN on bilateral scenes): the total normal force ∫_{Γ_C} p and
#: the maximal contact pressure max p (Nitsche: at the contact quadrature points; tresca-cr: over the edges)
UNILATERAL = ("normal_force", "max_pressure")
#: a quantity compared on Hertz only (``Scene.quantities``): the pressure's width 2√(∫p x²/∫p) about the symmetry
#: axis x = 0, a smooth functional of the pressure equal to Hertz's half-width a (∫p x² = a²∫p/4 for
#: p₀√(1 − x²/a²)); the codes report ∫_{Γ_C} p x² as ``pressure_x2``
HALF_WIDTH = "half_width"
ERRORS = ("err_h1_semi", "err_l2")


def stick_ends(s, dslip, eta):
    """The first and the last zero of the piecewise-linear interpolant of ψ = eta − |δu_τ| along Γ_C (arc
    length s); (NaN, NaN) when ψ has one sign (all of Γ_C sticks or all of it slips)."""
    s = np.asarray(s, dtype=float)
    m = eta - np.abs(np.asarray(dslip, dtype=float))
    order = np.argsort(s, kind="stable")
    s, m = s[order], m[order]
    change = np.nonzero((m[1:] > 0) != (m[:-1] > 0))[0]
    if change.size == 0:
        return math.nan, math.nan

    def zero(i):
        return float(s[i] + (s[i + 1] - s[i]) * m[i] / (m[i] - m[i + 1]))
    return zero(change[0]), zero(change[-1])


def slip_threshold(dslip, h, length):
    """η_h = (h/|Γ_C|)² max |δu_τ| (see the module docstring)."""
    return (h / length) ** 2 * float(np.max(np.abs(dslip)))


def summarise(raw, probes):
    """The row of compared quantities (and true errors when present) from a raw result dict."""
    length = probes["length"]
    row = {k: float(raw[k]) for k in ("h1_norm", "energy", "sigma_t_integral")}
    for i, v in enumerate(raw["u_tau_points"], start=1):
        row[f"u_tau_{i}"] = float(v)
    row["max_slip"] = float(np.max(np.abs(raw["u_tau_samples"])))
    s_q, dslip = np.asarray(raw["quad_s"], dtype=float), np.asarray(raw["quad_dslip"], dtype=float)
    start_d, end_d = probes.get("dirichlet_ends", (False, False))
    keep = ~((start_d & (s_q < raw["h"])) | (end_d & (s_q > length - raw["h"])))
    eta = slip_threshold(dslip, raw["h"], length)
    row["stick_a"], row["stick_b"] = stick_ends(s_q[keep], dslip[keep], eta)
    for k in UNILATERAL:
        row[k] = float(raw.get(k, math.nan))
    force, x2 = row["normal_force"], float(raw.get("pressure_x2", math.nan))
    row[HALF_WIDTH] = 2.0 * math.sqrt(x2 / force) if force > 0 and x2 >= 0 else math.nan
    for k in ERRORS:
        if k in raw:
            row[k] = float(raw[k])
    for k in ("dofs", "wall_s", "h"):
        row[k] = raw[k]
    return row

"""The compared quantities, from a code's raw result (the same definitions for every code).

Each solver reports, at the final time T: ‖u‖_H1 (``h1_norm``), its energy ½a(u,u) (``energy``; tresca-cr:
½a_h with the jump term), ∫_{Γ_C} σ_τ (``sigma_t_integral``: the consistent traction — the projected Nitsche
traction P, or tresca-cr's multiplier), u·τ at the three probe points (1/4, 1/2, 3/4 of Γ_C), u·τ at uniform
samples of Γ_C, and a stick flag at points of Γ_C (Nitsche: |σ_τ(u) − p δu_τ| < g_a at the contact quadrature
points; tresca-cr: the edge state). From them :func:`summarise` adds

* ``max_slip``  = max over the samples of |u·τ| (u_n is imposed, so u·τ is the slip relative to the foundation),
* ``stick_a``, ``stick_b`` = the first and the last stick↔slip transition along Γ_C (arc length from its
  start), each the zero of the piecewise-linear interpolant of the code's stick margin φ between the two
  neighbouring points where φ changes sign; NaN where nothing (or everything) sticks. φ is the semismooth
  active-set indicator, continuous in the solution: Nitsche φ = g_a − |σ_τ(u) − p δu_τ| (p the Nitsche
  parameter, δu_τ the last step's slip increment) at the contact quadrature points; tresca-cr the same
  formula with its multiplier σ_τ, its edge slip increment and p = γ_N (λ + 2μ)/|e| at the edge midpoints.
  φ > 0 sticks, φ < 0 slips. (The earlier definition, halfway between two points whose flags differ, moved
  in jumps of the quadrature spacing as h changed, and a three-level Richardson estimate of a quantity that
  jumps by ±h/2 has no meaning; the interpolated zero moves continuously with the solution.)
"""
from __future__ import annotations

import math

import numpy as np

#: quantities compared between codes, in table order
QUANTITIES = ("h1_norm", "energy", "u_tau_1", "u_tau_2", "u_tau_3", "sigma_t_integral", "stick_a", "stick_b",
              "max_slip")
ERRORS = ("err_h1_semi", "err_l2")


def stick_ends(s, margin):
    """The first and the last zero of the piecewise-linear interpolant of the stick margin along Γ_C (arc
    length); (NaN, NaN) when the margin has one sign (all of Γ_C sticks or all of it slips)."""
    s, m = np.asarray(s, dtype=float), np.asarray(margin, dtype=float)
    order = np.argsort(s, kind="stable")
    s, m = s[order], m[order]
    change = np.nonzero((m[1:] > 0) != (m[:-1] > 0))[0]
    if change.size == 0:
        return math.nan, math.nan

    def zero(i):
        return float(s[i] + (s[i + 1] - s[i]) * m[i] / (m[i] - m[i + 1]))
    return zero(change[0]), zero(change[-1])


def summarise(raw, length):
    """The row of compared quantities (and true errors when present) from a raw result dict."""
    row = {k: float(raw[k]) for k in ("h1_norm", "energy", "sigma_t_integral")}
    for i, v in enumerate(raw["u_tau_points"], start=1):
        row[f"u_tau_{i}"] = float(v)
    row["max_slip"] = float(np.max(np.abs(raw["u_tau_samples"])))
    row["stick_a"], row["stick_b"] = stick_ends(raw["quad_s"], raw["quad_margin"])
    for k in ERRORS:
        if k in raw:
            row[k] = float(raw[k])
    for k in ("dofs", "wall_s", "h"):
        row[k] = raw[k]
    return row

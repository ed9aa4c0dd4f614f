"""The compared quantities, from a code's raw result (the same definitions for every code).

Each solver reports, at the final time T: ‖u‖_H1 (``h1_norm``), its energy ½a(u,u) (``energy``; tresca-cr:
½a_h with the jump term), ∫_{Γ_C} σ_τ (``sigma_t_integral``: the consistent traction — the projected Nitsche
traction P, or tresca-cr's multiplier), u·τ at the three probe points (1/4, 1/2, 3/4 of Γ_C), u·τ at uniform
samples of Γ_C, and a stick flag at points of Γ_C (Nitsche: |σ_τ(u) − p δu_τ| < g_a at the contact quadrature
points; tresca-cr: the edge state). From them :func:`summarise` adds

* ``max_slip``  = max over the samples of |u·τ| (u_n is imposed, so u·τ is the slip relative to the foundation),
* ``stick_a``, ``stick_b`` = the first and the last stick↔slip transition along Γ_C (arc length from its
  start; the stick zone's ends where it is one interior interval, the slip zone's where that is), each
  halfway between the two neighbouring points whose flags differ; NaN where nothing (or everything) sticks.
"""
from __future__ import annotations

import math

import numpy as np

#: quantities compared between codes, in table order
QUANTITIES = ("h1_norm", "energy", "u_tau_1", "u_tau_2", "u_tau_3", "sigma_t_integral", "stick_a", "stick_b",
              "max_slip")
ERRORS = ("err_h1_semi", "err_l2")


def stick_ends(s, stick, length):
    """The first and the last stick↔slip transition along Γ_C (arc length), each halfway between the two
    points whose flags differ; (NaN, NaN) when all of Γ_C sticks or all of it slips."""
    s, stick = np.asarray(s, dtype=float), np.asarray(stick, dtype=bool)
    order = np.argsort(s, kind="stable")
    s, stick = s[order], stick[order]
    change = np.nonzero(stick[1:] != stick[:-1])[0]
    if change.size == 0:
        return math.nan, math.nan
    a, b = change[0], change[-1]
    return float(0.5 * (s[a] + s[a + 1])), float(0.5 * (s[b] + s[b + 1]))


def summarise(raw, length):
    """The row of compared quantities (and true errors when present) from a raw result dict."""
    row = {k: float(raw[k]) for k in ("h1_norm", "energy", "sigma_t_integral")}
    for i, v in enumerate(raw["u_tau_points"], start=1):
        row[f"u_tau_{i}"] = float(v)
    row["max_slip"] = float(np.max(np.abs(raw["u_tau_samples"])))
    row["stick_a"], row["stick_b"] = stick_ends(raw["quad_s"], raw["quad_stick"], length)
    for k in ERRORS:
        if k in raw:
            row[k] = float(raw[k])
    for k in ("dofs", "wall_s", "h"):
        row[k] = raw[k]
    return row

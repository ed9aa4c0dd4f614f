"""Richardson limits with Roache's grid convergence index (GCI) from a code's three finest levels.

With values Q₁, Q₂, Q₃ on h, h/r, h/r² (r = 2 here), d₁ = Q₂ − Q₁, d₂ = Q₃ − Q₂:

* monotone (d₁d₂ > 0, |d₂| < |d₁|) with observed order p = log(d₁/d₂)/log r in [½, p_max]:
  Q* = Q₃ + d₂/(rᵖ − 1), band GCI = 1.25 |d₂|/(rᵖ − 1)  (safety factor 1.25, three grids);
* otherwise (oscillating, stalled or p out of range): no extrapolation, Q* = Q₃ and the conservative band
  GCI = 3 |d₂|/(r^{p_th} − 1) with the theoretical order p_th (Roache's factor 3 for unconfirmed orders);
* d₂ = 0 (the value no longer changes): Q* = Q₃, GCI = 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from tresca_py.common import observed_order


@dataclass
class Limit:
    value: float
    gci: float
    p: float          # observed order (NaN when not monotone)
    extrapolated: bool


def limit(h, q, p_th=1.0, p_max=5.0):
    """Limit and band from the three finest (h, Q) pairs (h decreasing)."""
    (_, h2, h3), (q1, q2, q3) = h[-3:], q[-3:]
    if any(not math.isfinite(v) for v in (q1, q2, q3)):
        return Limit(math.nan, math.nan, math.nan, False)
    d1, d2 = q2 - q1, q3 - q2
    r = h2 / h3
    if d2 == 0.0:
        return Limit(q3, 0.0, math.nan, False)
    if d1 * d2 > 0 and abs(d2) < abs(d1):
        p = observed_order(abs(d1), abs(d2), r, 1.0)  # equal ratios h₁/h₂ = h₂/h₃ = r (uniform refinement)
        if 0.5 <= p <= p_max:
            return Limit(q3 + d2 / (r ** p - 1), 1.25 * abs(d2) / (r ** p - 1), p, True)
    return Limit(q3, 3.0 * abs(d2) / (r ** p_th - 1), math.nan, False)


#: rounding floor of a band, relative to the value: the codes stop Newton at a relative residual of 1e-10
#: (scikit-fem, GetFEM) or 1e-12 (tresca-cr), so values that no longer change between levels (e.g. ∫σ_τ =
#: −∫g_a when all of Γ_C slips) still differ between codes by about that much times a condition number
ROUNDING = 1e-8


def agree(a: Limit, b: Limit):
    """|Q*_a − Q*_b| ≤ GCI_a + GCI_b + the rounding floor (False when either limit is undefined)."""
    if not all(math.isfinite(v) for v in (a.value, b.value, a.gci, b.gci)):
        return False
    return abs(a.value - b.value) <= a.gci + b.gci + ROUNDING * max(abs(a.value), abs(b.value))

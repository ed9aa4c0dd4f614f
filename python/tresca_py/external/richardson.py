"""Richardson limits with Roache's grid convergence index (GCI) and the project's asymptotic-range check.

With the three finest values Q₁, Q₂, Q₃ on h, h/r, h/r² (r = 2 here), d₁ = Q₂ − Q₁, d₂ = Q₃ − Q₂:

* extrapolated when the three values converge monotonically (d₁d₂ > 0, |d₂| < |d₁|) with an observed order
  p = log(d₁/d₂)/log r in [½, p_max], and — given a fourth level Q₀ — the level pair (Q₀, Q₁) confirms p as
  ``tresca-cr study`` does (``src/study/richardson.rs``): with eⱼ = |Qⱼ − Q*|, |(e₀/e₁)/rᵖ − 1| ≤ RATIO_TOL.
  Then Q* = Q₃ + d₂/(rᵖ − 1), band GCI = 1.25 |d₂|/(rᵖ − 1) (safety factor 1.25, three grids);
* otherwise (oscillating, stalled, p out of range or not confirmed by the fourth level: the sequence is not
  in its asymptotic range) no extrapolation: Q* = Q₃ and the band GCI = 3 max(|d₁|, |d₂|)/(r^{p_th} − 1) with
  the theoretical order p_th (Roache's factor 3 for unconfirmed orders). The larger of the two differences:
  a sequence that changes direction can have an arbitrarily small last difference (Example 5.1's P1 corner
  slip: d₁ = 1.7e-6 then d₂ = −1.4e-8), which measures the crossing, not the distance to the limit;
* d₂ = 0 (the value no longer changes): Q* = Q₃, GCI = 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from tresca_py.common import observed_order

#: GCI-ratio tolerance of the fourth-level check, and Roache's safety factors with an observed order (three
#: levels) and with the order assumed: tresca-cr's ``RATIO_TOL``, ``FS_THREE`` and ``FS_TWO`` of
#: src/study/richardson.rs (python/tests/test_richardson_constants.py fails if they drift apart)
RATIO_TOL = 0.1
FS_THREE = 1.25
FS_TWO = 3.0


@dataclass
class Limit:
    value: float
    gci: float
    p: float          # observed order (NaN when not extrapolated)
    extrapolated: bool


def _confirmed(h, q, p, qstar):
    """The fourth-finest level's check of p (True when there is no fourth level to check with)."""
    if len(q) < 4:
        return True
    e0, e1 = abs(q[-4] - qstar), abs(q[-3] - qstar)
    if e1 == 0.0:
        return False
    ratio = (e0 / e1) / (h[-4] / h[-3]) ** p
    return math.isfinite(ratio) and abs(ratio - 1.0) <= RATIO_TOL


def limit(h, q, p_th=1.0, p_max=5.0):
    """Limit and band from the finest (h, Q) pairs (h decreasing; three or more levels)."""
    h, q = list(h), list(q)
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
            qstar = q3 + d2 / (r ** p - 1)
            if _confirmed(h, q, p, qstar):
                return Limit(qstar, FS_THREE * abs(d2) / (r ** p - 1), p, True)
    return Limit(q3, FS_TWO * max(abs(d1), abs(d2)) / (r ** p_th - 1), math.nan, False)


#: rounding floor of a band, relative to the value: the codes stop Newton at a relative residual of 1e-10
#: (scikit-fem, GetFEM) or 1e-12 (tresca-cr), so values that no longer change between levels (e.g. ∫σ_τ =
#: −∫g_a when all of Γ_C slips) still differ between codes by about that much times a condition number
ROUNDING = 1e-8


def agree(a: Limit, b: Limit):
    """|Q*_a − Q*_b| ≤ GCI_a + GCI_b + the rounding floor (False when either limit is undefined)."""
    if not all(math.isfinite(v) for v in (a.value, b.value, a.gci, b.gci)):
        return False
    return abs(a.value - b.value) <= a.gci + b.gci + ROUNDING * max(abs(a.value), abs(b.value))

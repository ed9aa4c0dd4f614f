"""tresca_py.verify.adaptive's checks on synthetic level tables: the rate check (fit and the last two windows),
the effectivity range and the DOF at which a route reaches an accuracy."""
import pytest

from tresca_py.verify import adaptive


def rows(rate, n=17, eff=lambda k: 5.0, growth=1.35):
    """Levels with DOF ×growth each and error ∝ DOF^(−rate)."""
    out = []
    for k in range(n):
        d = 100 * growth ** k
        out.append({"level": k, "unknowns": d, "error": d ** -rate, "effectivity": eff(k)})
    return out


def test_the_rate_check_accepts_the_optimal_rate_and_refuses_a_slower_one():
    """The system shall accept DOF^(−1/2) and refuse DOF^(−0.43) (the uniform rate of Example 5.1)."""
    fit_levels, windows = list(range(9, 17)), list(range(4, 17, 3))
    ok, fit, win, _ = adaptive.rate_check(rows(0.5), "error", fit_levels, windows, 0.5, adaptive.WINDOW_BAND)
    assert ok and fit == pytest.approx(0.5) and all(w == pytest.approx(0.5) for w in win)
    ok, _, _, _ = adaptive.rate_check(rows(0.43), "error", fit_levels, windows, 0.5, adaptive.WINDOW_BAND)
    assert not ok


def test_the_rate_check_refuses_a_late_slowdown_the_fit_hides():
    """The system shall refuse a sequence whose last windows leave the band even when the fit lies in it (the
    asymptotic-range check)."""
    r = rows(0.5)
    for k in range(14, 17):          # the error slows to DOF^(−0.3) over the last three levels
        r[k]["error"] = r[13]["error"] * (r[k]["unknowns"] / r[13]["unknowns"]) ** -0.3
    ok, fit, win, _ = adaptive.rate_check(r, "error", list(range(4, 17)), list(range(4, 17, 3)), 0.5, 0.12)
    assert abs(fit - 0.5) <= adaptive.FIT_BAND, "the fit alone would pass"
    assert not ok and abs(win[-1] - 0.5) > 0.12


def test_the_effectivity_check_refuses_a_drift_and_an_underestimate():
    """The system shall accept a constant effectivity, and refuse one that drifts like DOF^0.1 or one below 1."""
    assert adaptive.effectivity_check(rows(0.5))[0]
    assert not adaptive.effectivity_check(rows(0.5, eff=lambda k: 5.0 * (1.35 ** k) ** 0.1))[0]
    assert not adaptive.effectivity_check(rows(0.5, eff=lambda k: 0.9))[0]
    assert not adaptive.effectivity_check(rows(0.5, n=9))[0], "fewer than 10 levels"


def test_dof_for_interpolates_in_log_log_and_says_when_not_reached():
    """The system shall find the DOF of a power-law route's accuracy exactly, and None beyond its last level."""
    r = rows(0.5)
    assert adaptive.dof_for(r, "error", 2000 ** -0.5) == pytest.approx(2000)
    assert adaptive.dof_for(r, "error", 1e-9) is None


def test_ratio_trend_gives_the_dof_ratio_of_two_power_laws_at_each_uniform_level():
    """The system shall report, per uniform level, DOF_uniform / DOF_adaptive at the same error: for
    e_u = D^(−1/4) and e_a = D^(−1/2) that is D_u / D_u^(1/2) = D_u^(1/2), exactly (log-log interpolation
    of a power law)."""
    adaptive_rows = [{"level": k, "unknowns": 1.35 ** k, "error": 1.35 ** (-k / 2)} for k in range(40)]
    uniform_rows = [{"level": k, "unknowns": 100 * 4 ** k, "error": (100 * 4 ** k) ** -0.25} for k in range(6)]
    trend = adaptive.ratio_trend(adaptive_rows, uniform_rows, "error")
    assert [k for k, _ in trend] == [1, 2, 3, 4, 5]
    for k, r in trend:
        assert r == pytest.approx((100 * 4 ** k) ** 0.5, rel=1e-9)

"""The load-scaling requirement's judgement of which scales a results file can hold."""
from tresca_py.verify.stability.extremes import load_scale_limit

# Example 5.1's unit-load maxima (refine 2): smallest nonzero per-step max|u|, largest f32 view, energy
LIM = dict(u_min=2.015e-5, views=0.0995, energy=2.6e-4)


def test_loads_whose_views_underflow_are_not_representable():
    """The system shall count loads whose displacement lies below f32's normal range as not representable."""
    assert load_scale_limit(1e-300, LIM) == "underflow"
    assert load_scale_limit(1e-35, LIM) == "underflow"


def test_loads_within_both_ranges_are_representable():
    """The system shall require exact scaling for loads whose views and energy fit their formats."""
    for f in (1e-30, 1e-10, 1.0, 1e10, 1e36):
        assert load_scale_limit(f, LIM) is None


def test_loads_whose_views_or_energy_overflow_are_not_representable():
    """The system shall count loads past f32's range (views) or f64's (energy ~ f²) as not representable."""
    assert load_scale_limit(1e40, LIM) == "overflow"
    assert load_scale_limit(1e200, LIM) == "overflow"


def test_scales_at_a_limit_accept_either_outcome():
    """The system shall not judge a scale within rounding of a limit (3.4e38 / 0.0995 = 3.42e39)."""
    assert load_scale_limit(3.42e39, LIM) == "border"

"""The shared numerical helpers of the verification: observed orders and relative differences."""
import math

import numpy as np
import pytest

from tresca_py.common import observed_order, orders, rel_diff, rel_to


def test_orders_of_an_exact_power_law():
    """The system shall recover the order p of e = C x^p exactly (successive and fitted)."""
    x = [0.5, 0.25, 0.125, 0.0625]
    e = [3.0 * v ** 1.5 for v in x]
    succ, fit = orders(x, e)
    assert succ == pytest.approx([1.5] * 3, abs=1e-12)
    assert fit == pytest.approx(1.5, abs=1e-12)
    assert observed_order(e[0], e[1], x[0], x[1]) == pytest.approx(1.5, abs=1e-12)


def test_orders_see_a_pre_asymptotic_level():
    """The fitted order differs from the successive ones when the first level is off the law (the order
    check can fail)."""
    x = [0.5, 0.25, 0.125, 0.0625]
    e = [v for v in x]
    e[0] *= 4
    succ, fit = orders(x, e)
    assert succ[0] == pytest.approx(1 + math.log2(4))
    assert succ[1:] == pytest.approx([1.0, 1.0])
    assert abs(fit - 1.0) > 0.3


def test_rel_diff_is_symmetric_and_scaled():
    a, b = np.array([1.0, -2.0, 4.0]), np.array([1.0, -2.0, 3.0])
    assert rel_diff(a, b) == rel_diff(b, a) == pytest.approx(0.25)
    assert rel_diff(np.zeros(3), np.zeros(3)) == 0.0
    assert rel_diff([0.0], [1e-300]) == pytest.approx(1.0)


def test_rel_to_is_relative_to_the_reference():
    assert rel_to([2.0, 0.0], [1.0, 0.0]) == pytest.approx(1.0)
    assert rel_to([1e-3], [0.0]) == pytest.approx(1e-3)  # a vanishing reference: absolute

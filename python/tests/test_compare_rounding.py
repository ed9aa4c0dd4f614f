"""The cross-check's comparison of true errors (tresca_py.compare): errors at rounding level (a scene whose exact
solution CR reproduces, such as verification/cases/floating_block.toml) are not compared relatively, errors of a
discretisation are."""
import numpy as np
import pytest

from tresca_py import compare


def fake(errors, energy):
    """A loaded file (compare.load's dict) on two edges and two time nodes, without contact."""
    return {"times": np.array([0.0, 1.0]), "u": np.ones((2, 2, 2)), "mid": np.array([[0.0, 0.0], [1.0, 0.0]]),
            "energy": np.array(energy), "solver": "fake", "errors": {"energy": np.array(errors)}}


@pytest.fixture
def files(monkeypatch):
    def use(a, b):
        loaded = {"a": a, "b": b}
        monkeypatch.setattr(compare, "load", lambda p: loaded[p])
        return compare.compare_files("a", "b")
    return use


def test_the_system_shall_not_compare_true_errors_at_rounding_level_relatively(files):
    # |||u_h||| = (2·2)^(1/2) = 2: errors of 5e-11 and 3e-11 (above the absolute floor 1e-12) are 2.5e-11 of it,
    # below ROUNDING_LEVEL
    r = files(fake([0.0, 5e-11], [0.0, 2.0]), fake([0.0, 3e-11], [0.0, 2.0]))
    assert r["derr"] == 0.0


def test_the_system_shall_compare_true_errors_of_a_discretisation_relatively(files):
    # errors of 1e-3 of |||u_h||| that differ by 40 %: a failure the floor must not hide
    r = files(fake([0.0, 2e-4], [0.0, 0.02]), fake([0.0, 1.2e-4], [0.0, 0.02]))
    assert r["derr"] == pytest.approx(0.4)

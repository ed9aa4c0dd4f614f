"""Derivation and checks of the manufactured unilateral cases (tresca_py.mms.signorini), run by
verification/mms/derive.py: the contact data (gap, the surface load sigma(u)n - r on Gamma_C, g_a or the Coulomb
coefficient) printed and round-tripped like every other string; the derivative checks of tresca_py.mms.checks;
Signorini and the friction law from the printed data (tresca_py.mms.signorini_law); and a self-test: wrong
variants (negative pressure, penetration, a pressure where separated, a threshold too small, slip along the
friction traction, a Coulomb threshold off the exact pressure) must each be rejected."""
import numpy as np
import sympy as sp

from tresca_py.mms.checks import check_derivatives, check_roundtrip, sample_times
from tresca_py.mms.derive import CheckFailed, derive, printed
from tresca_py.mms.elasticity import side_normal_exact
from tresca_py.mms.signorini import SIGNORINI_CASES, R, case_coulomb, case_signorini_moving, x
from tresca_py.mms.signorini_law import check_signorini_law
from tresca_py.mms.signorini_stop import case_signorini_stop

#: every unilateral case that verification/mms/derive.py writes
UNILATERAL_CASES = SIGNORINI_CASES + [case_signorini_stop]


def derive_signorini(case):
    """tresca_py.mms.derive.derive, plus the printed contact data of every contact side: ``gap_SIDE``, the surface
    load ``ct_SIDE_1``, ``ct_SIDE_2`` = sigma(u)n - r (r = -p n + lt tau) and ``coulomb`` for a Coulomb case."""
    d = derive(case)
    c = case["contact"]
    for side in [s for s, k in case["kinds"].items() if k == "contact"]:
        n = side_normal_exact(case["corners"], side)
        tau = sp.Matrix([-n[1], n[0]])
        r = -c["pressure"] * n + c["lt"] * tau
        load = d["S"] * n - r
        d["sym"]["gap_%s" % side] = c["gap"]
        d["sym"]["ct_%s_1" % side], d["sym"]["ct_%s_2" % side] = load[0], load[1]
    if c["friction"] == "coulomb":
        d["sym"]["coulomb"] = c["bound"]
    d["str"] = printed(case["name"], d["sym"])
    return d


def run_checks(case, log=print):
    """Derive ``case`` and check it (round trip, derivatives, Signorini and friction on a fine grid); returns the
    derived case."""
    rng = np.random.default_rng(20261128)
    d = derive_signorini(case)
    check_roundtrip(d, rng, log)
    check_derivatives(d, rng, log)
    times = sample_times(d, 401)
    for side in [s for s, k in d["kinds"].items() if k == "contact"]:
        check_signorini_law(d, side, np.linspace(0, 1, 1001), times, log=log)
    return d


def _mutant(make, **contact):
    c = make()
    c["contact"] = dict(c["contact"], **contact)
    return c


def mutants():
    """What the checks must reject: name -> case maker."""
    m = case_signorini_moving()["contact"]
    cm = case_coulomb()["contact"]
    return {
        "negative pressure": lambda: _mutant(case_signorini_moving, pressure=m["pressure"] - R(1, 100)),
        "penetration (gap too small)": lambda: _mutant(case_signorini_moving, gap=m["gap"] - R(1, 1000)),
        "pressure where separated": lambda: _mutant(case_signorini_moving, pressure=m["pressure"] + R(1, 100)),
        "g_a 1% too small": lambda: dict(case_signorini_moving(), g_a=case_signorini_moving()["g_a"] * R(99, 100)),
        "slip along the friction traction": lambda: _mutant(case_signorini_moving, lt=-m["lt"]),
        "Coulomb F 1% too small": lambda: _mutant(case_coulomb, bound=cm["bound"] * R(99, 100)),
        "Coulomb threshold off the pressure": lambda: _mutant(case_coulomb, lt=cm["lt"] * (1 + x / 10)),
        "Coulomb: friction traction where separated": lambda: _mutant(case_coulomb, lt=cm["lt"] - R(1, 100)),
        "slip continues after the traction leaves the bound": lambda: case_signorini_stop(stops=False),
    }


def selftest():
    """Every mutant of ``mutants()`` must fail the checks."""
    for what, make in mutants().items():
        try:
            run_checks(make(), log=lambda msg: None)
        except CheckFailed as err:
            print("   selftest: %-45s caught: %s" % (what, err))
            continue
        raise CheckFailed("selftest: mutant '%s' passed the checks" % what)

"""The manufactured unilateral cases (tresca_py.mms.signorini): the committed scenes regenerate byte for byte,
every case satisfies Signorini and its friction law at the sample points from its printed data, and data that
break a law are rejected."""
import os

import pytest

from tresca_py.common import CASES
from tresca_py.mms.derive import CheckFailed
from tresca_py.mms.scene_toml import scene_text
from tresca_py.mms.signorini import SIGNORINI_CASES
from tresca_py.mms.signorini_checks import UNILATERAL_CASES, derive_signorini, mutants, run_checks

QUIET = dict(log=lambda msg: None)


@pytest.mark.parametrize("make", UNILATERAL_CASES, ids=lambda m: m.__name__)
def test_the_system_shall_regenerate_the_committed_unilateral_scenes_byte_for_byte(make):
    """The system shall write verification/cases/mms_signorini_*.toml exactly as derived from the case."""
    d = derive_signorini(make())
    with open(os.path.join(CASES, d["name"] + ".toml")) as fh:
        assert scene_text(d) == fh.read()


@pytest.mark.parametrize("make", UNILATERAL_CASES, ids=lambda m: m.__name__)
def test_the_system_shall_derive_unilateral_cases_that_satisfy_signorini_and_friction(make):
    """The system shall derive data whose contact reaction satisfies p >= 0, u.n <= g, p (u.n - g) = 0 and the
    friction law (Tresca or Coulomb) at every sample, with both transition points inside Gamma_C."""
    d = run_checks(make(), **QUIET)
    assert d["expect"]["separation_to_contact"] and (d["expect"]["stick_to_slip"] or d["expect"]["slip_to_stick"])


@pytest.mark.parametrize("what", sorted(mutants()))
def test_the_system_shall_reject_unilateral_data_that_break_a_law(what):
    """The system shall reject a case whose contact data violate Signorini or the friction law."""
    with pytest.raises(CheckFailed):
        run_checks(mutants()[what](), **QUIET)


def test_the_system_shall_keep_the_near_incompressible_case_free_of_lambda():
    """The system shall make the near-incompressible case divergence-free (lambda/mu >= 1e4), so that no printed
    datum depends on lambda."""
    d = derive_signorini(SIGNORINI_CASES[1]())
    assert d["lam"] / d["mu"] >= 10000
    assert all("10000" not in v for k, v in d["str"].items())

"""The manufactured-solution derivation (tresca_py.mms): its printed data read back (by the solvers' reading)
equal to the sympy originals, the committed scenes regenerate byte for byte, and the checks reject wrong data."""
import os

import numpy as np
import pytest

from tresca_py.common import CASES
from tresca_py.expr import parse
from tresca_py.mms.cases import CASES as MMS_CASES
from tresca_py.mms.cases import case_elastic, case_stick_to_slip
from tresca_py.mms.checks import check_derivatives, check_roundtrip
from tresca_py.mms.derive import CheckFailed, derive
from tresca_py.mms.scene_toml import scene_text


@pytest.mark.parametrize("make", MMS_CASES, ids=lambda m: m.__name__)
def test_the_system_shall_regenerate_the_committed_manufactured_scenes_byte_for_byte(make):
    d = derive(make())
    with open(os.path.join(CASES, d["name"] + ".toml")) as fh:
        assert scene_text(d) == fh.read()


def test_the_system_shall_read_back_every_printed_expression_as_derived():
    d = derive(case_stick_to_slip())
    check_roundtrip(d, np.random.default_rng(1), log=lambda msg: None)
    check_derivatives(d, np.random.default_rng(2), log=lambda msg: None)


def test_the_system_shall_reject_a_body_force_that_does_not_balance_the_stress():
    d = derive(case_elastic())
    d["str"]["f1"] = "(" + d["str"]["f1"] + "+(1/1000))"
    d["parsed"] = {k: parse(v, k) for k, v in d["str"].items()}
    with pytest.raises(CheckFailed, match="equilibrium"):
        check_derivatives(d, np.random.default_rng(2), log=lambda msg: None)

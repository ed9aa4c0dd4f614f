"""The requirements of make verify are declared once, completely, and verification/README.md's table is the
one generated from them."""
import os

import pytest

from tresca_py.common import ROOT
from tresca_py.verify import readme
from tresca_py.verify.requirements import REQUIREMENTS, find

# result ids the studies record (tresca_py/verify/*.py, the check scripts): each must belong to exactly one
# declared requirement
RECORDED = ["E1-rect-energy", "E1-rect-L2", "E2-rotated-energy", "E2-rotated-L2", "C1-front-energy",
            "C2-rotated-energy", "K1-mms_stop", "K2-stick-to-slip", "J1-joint", "P1-paper-orders", "P2-paper-runs",
            "P3-paper-estimate", "R1-estimate-effectivity", "R2-estimate-refuses", "R3-differences", "O1-clients",
            "O2-interrupted", "V1-paraview", "X-mms_front-r1", "X-mpi-mms_stop-r0", "D1-distributed-agree",
            "D2-distributed-memory", "PL1-mms_front", "PL2-mms_stop", "S1-stability", "S12-stability", "F1-fuzz",
            "EB1-external", "EB1-clients", "EB1-audit", "EB1-audit-run-trapezoid", "HZ1-hertz-discretisation",
            "HZ2-hertz-formulas", "HZ3-hertz-model-order", "HZ4-hertz-polygon", "EB1-hertz"]


def test_ids_are_unique():
    """The system shall declare every requirement id once."""
    ids = [r.id for r in REQUIREMENTS]
    assert len(ids) == len(set(ids))


def test_every_requirement_is_complete():
    """The system shall give every requirement a statement, a command and a reference file that exists (or
    none, when its evidence is the command's output)."""
    for r in REQUIREMENTS:
        assert r.statement and r.command, r.id
        assert not r.statement[0].isupper(), f"{r.id}: the statement completes 'The solver shall …'"
        assert r.sentence.startswith("The solver shall ")
        if r.reference and "*" not in r.reference and r.reference.startswith("reference/"):
            assert os.path.exists(os.path.join(ROOT, r.reference)), f"{r.id}: {r.reference} missing"


@pytest.mark.parametrize("rid", RECORDED)
def test_every_recorded_id_is_declared(rid):
    """The system shall map every result id the studies record to exactly one declared requirement."""
    assert find(rid) in REQUIREMENTS


def test_an_undeclared_id_is_refused():
    """The system shall refuse a result id that no requirement declares, and the timing requirements PL3 and
    PL4 are no longer part of make verify."""
    for rid in ["Z9-nothing", "PL3-mms_front", "PL4-mms_stop", "E1", "E1-rectangle"]:
        with pytest.raises(KeyError):
            find(rid)


def test_readme_table_is_generated_from_the_requirements():
    """The system shall keep verification/README.md's table equal to the one generated from the registry
    (`make reference` regenerates it)."""
    text = open(readme.README, encoding="utf-8").read()
    assert readme.with_table(text) == text, "stale table: run `make reference`"
    for r in REQUIREMENTS:
        assert f"| {r.id} | {r.statement} |" in text


def test_generated_table_changes_with_the_registry():
    """The README check can fail: a changed statement gives a different table."""
    text = open(readme.README, encoding="utf-8").read()
    changed = [type(r)(r.id, r.statement + " (changed)", r.command, r.reference, r.pattern) for r in REQUIREMENTS]
    assert readme.with_table(text, changed) != text

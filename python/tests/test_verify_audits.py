"""EB1: make verify's harness audits the energy of every results file tresca-cr writes during a study
(tresca_py.verify.audits), and a damaged file fails it."""
import shutil
import subprocess

import h5py
import pytest

from tresca_py.common import CASES
from tresca_py.verify import audits
from tresca_py.verify.harness import Harness


@pytest.fixture(scope="module")
def front(tmp_path_factory, rust_bin):
    """A tresca-cr run of mms_front (slips: friction dissipation > 0)."""
    out = tmp_path_factory.mktemp("a1") / "front.h5"
    subprocess.run([rust_bin, "run", f"{CASES}/mms_front.toml", "--refine", "1", "--steps", "8", "-q",
                    "-o", str(out)], check=True, capture_output=True)
    return out


def test_the_system_shall_audit_every_tresca_file_a_study_writes(front, tmp_path):
    study = tmp_path / "study"
    study.mkdir()
    shutil.copy(front, study / "old.h5")
    before = audits.snapshot(str(study))  # an earlier study's file: not this study's
    shutil.copy(front, study / "a.h5")
    with h5py.File(study / "python.h5", "w") as f:  # a file without the audit series: listed as skipped
        f.create_group("tresca/steps")
    hs = Harness(out=str(tmp_path / "hs"), echo=False)
    checked = audits.audit_study(hs, "clients", before, root=str(study))
    assert len(checked) == 1 and "a.h5" in checked[0], checked
    r = hs.results[-1]
    assert r.id == "EB1-clients" and r.passed, r.measured
    assert "1 files, 0 problems" in r.measured and "skipped 1" in r.measured, r.measured


def test_the_system_shall_record_nothing_for_a_study_without_results_files(tmp_path):
    hs = Harness(out=str(tmp_path / "hs"), echo=False)
    assert audits.audit_study(hs, "elastic", {}, root=str(tmp_path)) == []
    assert hs.results == []


@pytest.mark.parametrize("damage", ["wrong friction sign", "residual hidden", "unreadable"])
def test_the_system_shall_fail_the_study_when_one_file_does_not_balance(front, tmp_path, damage):
    study = tmp_path / "study"
    study.mkdir()
    shutil.copy(front, study / "good.h5")
    bad = study / "bad.h5"
    shutil.copy(front, bad)
    with h5py.File(bad, "r+") as f:
        g = f["tresca/steps"]
        if damage == "wrong friction sign":
            # a friction force of the wrong sign does work instead of dissipating it
            g["friction_dissipation"][...] = -g["friction_dissipation"][()]
            g["balance_residual"][...] = g["balance_residual"][()] - 2 * g["friction_dissipation"][()]
        elif damage == "residual hidden":
            g["balance_residual"][...] = 0.0 * g["balance_residual"][()]
            g["stored_energy"][-1] = 1.01 * g["stored_energy"][-1]
        else:
            del f["tresca/u"]
    hs = Harness(out=str(tmp_path / "hs"), echo=False)
    checked = audits.audit_study(hs, "external", {}, root=str(study))
    assert len(checked) == 2
    r = hs.results[-1]
    assert r.id == "EB1-external" and not r.passed, r.measured
    assert "bad.h5" in r.measured.split("problems")[1].split(";")[0], r.measured


def test_the_system_shall_run_every_scene_once_for_its_audit(tmp_path, monkeypatch, rust_bin):
    """The study `audit` runs each scene of its directories with a results file; a scene that does not run is
    a failed EB1-audit-run-<name>, and the files it wrote are audited as EB1-audit."""
    cases = tmp_path / "cases"
    cases.mkdir()
    shutil.copy(f"{CASES}/elastic_rect.toml", cases / "good.toml")
    (cases / "broken.toml").write_text("[mesh]\ncells = [1]\n")
    monkeypatch.setattr(audits, "CASE_DIRS", (str(cases),))
    hs = Harness(out=str(tmp_path / "hs"), echo=False)
    before = audits.snapshot(hs.out)
    audits.run_cases(hs, quick=True)
    checked = audits.audit_study(hs, "audit", before)
    assert [r.id for r in hs.results] == ["EB1-audit-run-broken", "EB1-audit"]
    assert not hs.results[0].passed and hs.results[1].passed
    assert len(checked) == 1 and "good.h5" in checked[0]

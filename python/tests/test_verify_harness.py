"""The harness records results against the declared requirements, writes only under its output directory,
and `make reference` publishes what it staged."""
import json
import os

import pytest

from tresca_py.verify.harness import Harness, publish


def test_results_take_their_defaults_from_the_registry(tmp_path):
    """The system shall record a result with its requirement's statement, command and reference."""
    hs = Harness(out=str(tmp_path), echo=False)
    assert hs.require("K1-mms_stop", True, "fit 1.000")
    r = hs.results[0]
    assert r.statement.startswith("The solver shall converge with order 1")
    assert r.command.startswith("tresca-cr study verification/cases/mms_stop.toml")
    assert r.reference == "reference/k_study_mms_stop.md"


def test_undeclared_ids_are_refused(tmp_path):
    hs = Harness(out=str(tmp_path), echo=False)
    with pytest.raises(KeyError):
        hs.require("Q7-unknown", True, "")


def test_report_exit_status_and_files(tmp_path):
    """The system shall exit 1 when a requirement fails (or none ran), and write summary.md and results.json
    into its output directory only."""
    hs = Harness(out=str(tmp_path), echo=False)
    assert hs.report() == 1  # nothing recorded
    hs.require("F1-fuzz", True, "3 fuzzers")
    assert hs.report() == 0
    hs.require("J1-joint", False, "fit 0.7")
    hs.not_run("paper", "boom")
    assert hs.report("header", partial=True) == 1
    assert {"summary.md", "summary_partial.md", "results.json", "reference"} <= set(os.listdir(tmp_path))
    res = json.load(open(tmp_path / "results.json"))
    assert [r["id"] for r in res] == ["F1-fuzz", "J1-joint", "paper-run"]
    assert [r["passed"] for r in res] == [True, False, False]


def test_script_requirement_lists_round_trip(tmp_path):
    """A script's requirement list (Harness.dump) reads back into another harness unchanged."""
    a = Harness(out=str(tmp_path / "a"), echo=False)
    a.require("S1-stability", True, "5e-14", statement="E scaling: exact")
    a.dump(str(tmp_path / "a.json"))
    b = Harness(out=str(tmp_path / "b"), echo=False)
    b.record_list(str(tmp_path / "a.json"), "cmd", "S0-stability")
    assert b.results == a.results
    b.record_list(str(tmp_path / "missing.json"), "cmd", "S0-stability")
    assert b.results[-1].id == "S0-stability-run" and not b.results[-1].passed


def test_publish_copies_the_staged_files(tmp_path):
    """`make reference` shall copy the staged files (and a full run's summary) into reference/."""
    hs = Harness(out=str(tmp_path / "out"), echo=False)
    hs.write("h_mms_front.md", "table\n")
    hs.require("F1-fuzz", True, "ok")
    hs.report()
    ref = tmp_path / "reference"
    ref.mkdir()
    names = publish(out=hs.out, reference=str(ref))
    assert names == ["h_mms_front.md", "summary.md"]
    assert (ref / "h_mms_front.md").read_text() == "table\n"


def test_publish_copies_a_staged_folder(tmp_path):
    """`make reference` shall copy a study's staged folder (reference/adaptive/) into reference/, replacing the
    files of the same name and keeping the others."""
    hs = Harness(out=str(tmp_path / "out"), echo=False)
    os.makedirs(hs.path("adaptive/lshape"))
    hs.write("adaptive/study.md", "new\n")
    hs.write("adaptive/lshape/mesh_0.png", "png\n")
    ref = tmp_path / "reference"
    (ref / "adaptive").mkdir(parents=True)
    (ref / "adaptive" / "study.md").write_text("old\n")
    (ref / "adaptive" / "kept.csv").write_text("kept\n")
    assert publish(out=hs.out, reference=str(ref)) == ["adaptive"]
    assert (ref / "adaptive" / "study.md").read_text() == "new\n"
    assert (ref / "adaptive" / "lshape" / "mesh_0.png").read_text() == "png\n"
    assert (ref / "adaptive" / "kept.csv").read_text() == "kept\n"

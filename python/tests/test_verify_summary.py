"""The CLI's --json summary, read from a real `tresca-cr` on a tiny case (src/cli/summary.rs)."""
import os

import pytest

from tresca_py.common import BIN, case
from tresca_py.verify import summary


@pytest.fixture(scope="module")
def binary():
    assert os.path.exists(BIN), f"{BIN} missing: make build"
    return BIN


def test_run_summary(binary):
    """The system shall write a run's sizes, set-up phases, per-step statistics and true errors."""
    s, p = summary.run([binary, "run", case("mms_front"), "--refine", "0", "--steps", "4", "-q"])
    assert p.returncode == 0
    assert s["command"] == "run" and s["status"] == "completed" and s["scene"].endswith("mms_front.toml")
    assert s["version"] and s["commit"]
    r = s["run"]
    assert r["refine"] == 0 and r["steps"] == 4 and r["unknowns"] > 0 and r["contact_edges"] > 0
    steps = r["step_stats"]
    assert [x["n"] for x in steps] == [0, 1, 2, 3, 4]
    assert sum(x["iterations"] for x in steps) == r["iterations"]
    assert max(x["residual"] for x in steps) == r["max_residual"] <= 1e-10
    assert all(x["stick"] + x["slip"] == r["contact_edges"] for x in steps)
    energy = max(x["errors"]["energy"] for x in steps)
    assert summary.max_errors(s)[0] == energy > 0
    assert len(summary.setup_times(s)) == 5 and all(t >= 0 for t in summary.setup_times(s))
    assert s["study"] is None and s["plan"] is None and s["check"] is None


def test_study_and_check_summaries(binary):
    """The system shall write a study's levels and estimates, and check's mesh and estimate."""
    s, _ = summary.run([binary, "study", case("mms_front"), "--levels", "0:4,1:4,2:4"])
    st = s["study"]
    assert [lv["refine"] for lv in st["levels"]] == [0, 1, 2]
    assert st["estimates"]["size"] == "h"
    assert st["levels"][1]["consecutive"] is not None and st["levels"][0]["max_err"]["energy"] > 0
    c, _ = summary.run([binary, "check", case("mms_front"), "--refine", "1"])
    assert c["check"]["unknowns"] > 0 and c["check"]["exact"] is True and c["check"]["memory"] > 0


def test_stopped_run_still_writes_its_summary(binary, tmp_path):
    """A run stopped by a solver failure shall write a summary saying why (and exit non-zero)."""
    scene = tmp_path / "stop.toml"
    text = open(case("paper_example_5_1")).read().replace('g_a = "0.0012"', 'g_a = "0.02"')
    text = text.replace('method = "ssn"', 'method = "uzawa"\nuzawa_step = 1e9\nmax_iter = 50')
    scene.write_text(text)
    s, p = summary.run([binary, "run", str(scene), "-q"], check=False)
    assert p.returncode == 1
    assert s["status"].startswith("stopped:")


def test_bad_json_path_is_refused(binary, tmp_path):
    """A --json path in a missing directory shall be refused before any work, naming it."""
    import subprocess
    p = subprocess.run([binary, "run", case("mms_front"), "--json", str(tmp_path / "no" / "s.json")],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "does not exist" in p.stderr

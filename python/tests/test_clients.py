"""The results file as real clients read it and the whole-suite cross-check, run as the verification
scripts that own them (formerly verification/python_tests.py): VTK, meshio and h5py read a fresh Rust run
(scripts/check_results.py); killed, stopped and resumed runs leave readable files
(verification/interrupted_runs.py); ParaView opens them (verification/paraview_check.py, skipped with a
message where pvpython is absent); Rust == scikit-fem == dolfinx on every scene of verification/cases at one
mesh level (verification/cross_check.py --quick)."""
import os
import shutil
import sys

import pytest

from conftest import run
from tresca_py.common import ROOT

PY = sys.executable


def check(cmd):
    p = run(cmd)
    assert p.returncode == 0, f"{' '.join(cmd)} exited {p.returncode}:\n{p.stdout[-3000:]}\n{p.stderr[-3000:]}"
    return p


def test_the_system_shall_write_results_that_vtk_meshio_and_h5py_read(rust_bin, tmp_path):
    h5 = str(tmp_path / "ex51.h5")
    check([rust_bin, "run", "verification/cases/paper_example_5_1.toml", "--refine", "2", "--steps", "160", "-q",
           "-o", h5, "--force"])
    check([PY, "scripts/check_results.py", h5])


@pytest.mark.study
def test_the_system_shall_leave_readable_files_after_killed_stopped_and_resumed_runs(rust_bin):
    check([PY, "verification/interrupted_runs.py"])


# study-sized (pvpython on three runs and three readers): make verify runs it as V1 and T1; make test keeps
# paraview_view.py on a finished run (test_hostile_tools.py, TestParaviewView)
@pytest.mark.study
def test_the_system_shall_write_files_paraview_opens(rust_bin):
    check([PY, "verification/paraview_check.py", "--skip-missing"])


@pytest.mark.mpi
@pytest.mark.study
def test_the_system_shall_agree_across_rust_skfem_and_dolfinx_on_every_case(rust_bin):
    os.makedirs(os.path.join(ROOT, "out"), exist_ok=True)
    check([PY, "verification/cross_check.py", "--quick", "--json", "out/cross_check_quick.json"])


FAKE_PVPYTHON = """#!/bin/sh
# counts its calls; the first call of a run with $1 = lose-x loses its X server as pvpython does
n=$(cat "$0.calls" 2>/dev/null || echo 0); n=$((n + 1)); echo $n > "$0.calls"
if [ "$1" = lose-x ] && [ $n -eq 1 ]; then
  echo "ERROR: In vtkXOpenGLRenderWindow: bad X server connection." >&2; exit 134
fi
if [ "$1" = fail ]; then echo "error: a script failure" >&2; exit 1; fi
echo "display $DISPLAY"
"""


@pytest.mark.skipif(not shutil.which("Xvfb"), reason="Xvfb missing (make paraview)")
@pytest.mark.parametrize("arg,calls,rc", [("lose-x", 2, 0), ("fail", 1, 1), ("ok", 1, 0)])
def test_the_system_shall_repeat_a_pvpython_run_only_when_it_lost_its_x_server(tmp_path, monkeypatch, arg, calls,
                                                                               rc):
    """The system shall run pvpython on an X server of its own and repeat a run once, on a new server, only when
    pvpython lost its X server (tresca_py.xvfb): a script's own failure is reported, never retried."""
    from tresca_py.xvfb import VirtualDisplay
    fake = tmp_path / "pvpython"
    fake.write_text(FAKE_PVPYTHON)
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{tmp_path}{os.pathsep}{os.environ['PATH']}")
    with VirtualDisplay() as display:
        p = display.pvpython([arg], timeout=60)
    assert p.returncode == rc, p.stderr
    assert int((tmp_path / "pvpython.calls").read_text()) == calls
    if rc == 0:
        assert p.stdout.startswith("display :"), p.stdout

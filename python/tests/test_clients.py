"""The results file as real clients read it and the whole-suite cross-check, run as the verification
scripts that own them (formerly verification/python_tests.py): VTK, meshio and h5py read a fresh Rust run
(scripts/check_results.py); killed, stopped and resumed runs leave readable files
(verification/interrupted_runs.py); ParaView opens them (verification/paraview_check.py, skipped with a
message where pvpython is absent); Rust == scikit-fem == dolfinx on every scene of verification/cases at one
mesh level (verification/cross_check.py --quick)."""
import os
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


def test_the_system_shall_leave_readable_files_after_killed_stopped_and_resumed_runs(rust_bin):
    check([PY, "verification/interrupted_runs.py"])


def test_the_system_shall_write_files_paraview_opens(rust_bin):
    check([PY, "verification/paraview_check.py", "--skip-missing"])


@pytest.mark.mpi
def test_the_system_shall_agree_across_rust_skfem_and_dolfinx_on_every_case(rust_bin):
    os.makedirs(os.path.join(ROOT, "out"), exist_ok=True)
    check([PY, "verification/cross_check.py", "--quick", "--json", "out/cross_check_quick.json"])

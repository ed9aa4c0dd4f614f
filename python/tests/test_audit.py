"""The energy audit of a results file (tresca_py.audit, run by scripts/check_results.py)."""
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from tresca_py import audit
from tresca_py.common import CASES, ROOT


@pytest.fixture(scope="module")
def front(tmp_path_factory, rust_bin):
    out = tmp_path_factory.mktemp("audit") / "front.h5"
    subprocess.run([rust_bin, "run", f"{CASES}/mms_front.toml", "--refine", "1", "--steps", "16", "-q",
                    "-o", str(out)], check=True, capture_output=True)
    return out


def check_results(path):
    return subprocess.run([sys.executable, f"{ROOT}/scripts/check_results.py", str(path)], capture_output=True,
                          text=True)


def test_the_system_shall_find_the_energy_balance_of_a_rust_run(front):
    with h5py.File(front) as f:
        completed = int(f["tresca/steps"].attrs["completed"])
    a = audit.read(front, completed)
    assert a is not None and audit.problems(a) == []
    assert a["friction_dissipation"].max() > 0, "mms_front slips: the audit must see dissipation"
    r = check_results(front)
    assert r.returncode == 0 and "energy balance" in r.stdout, r.stdout + r.stderr


@pytest.mark.parametrize("damage", ["wrong friction sign", "residual hidden"])
def test_the_system_shall_refuse_a_run_whose_energy_does_not_balance(front, tmp_path, damage):
    bad = tmp_path / "bad.h5"
    shutil.copy(front, bad)
    shutil.copy(front.with_suffix(".xdmf"), tmp_path / "bad.xdmf")
    with h5py.File(bad, "r+") as f:
        g = f["tresca/steps"]
        if damage == "wrong friction sign":
            # a friction force of the wrong sign does work instead of dissipating it
            g["friction_dissipation"][...] = -g["friction_dissipation"][()]
            g["balance_residual"][...] = g["balance_residual"][()] - 2 * g["friction_dissipation"][()]
        else:
            g["balance_residual"][...] = 0.0 * g["balance_residual"][()]
            g["stored_energy"][-1] = 1.01 * g["stored_energy"][-1]
    with h5py.File(bad) as f:
        a = audit.read(bad, int(f["tresca/steps"].attrs["completed"]))
    assert audit.problems(a, audit.rounding(bad, audit.largest_work(a))), damage


def test_the_system_shall_allow_rounding_that_grows_with_unknowns_stiffness_and_bound(front, tmp_path):
    """The balance's rounding allowance is γ_N (λ+2μ)/μ + 4ε max|u| Σ ḡ_e|e| / scale: N ε/(1 − N ε) ·
    2(1−ν)/(1−2ν) and the friction bound's, 0 without attributes."""
    with h5py.File(front) as f:
        g = f["tresca"]
        n, nu = int(g.attrs["n_dofs"]), float(g.attrs["nu"])
        umax = float(abs(g["u"][:]).max())
        ends = g["mesh/points"][:][g["mesh/edges"][:][g["contact/edges"][:]]]
        bound = float((abs(g["contact/g"][:]) * ((ends[:, 1] - ends[:, 0]) ** 2).sum(axis=1) ** 0.5).sum())
    solve = n * audit.EPS / (1 - n * audit.EPS) * 2 * (1 - nu) / (1 - 2 * nu)
    assert audit.rounding(front, 2.0) == pytest.approx(solve + 4 * audit.EPS * umax * bound / 2.0, rel=1e-12)
    assert bound > 0 and 0 < audit.rounding(front, 2.0) < 1e-12
    bare = tmp_path / "bare.h5"
    with h5py.File(bare, "w") as f:
        f.create_group("tresca")
    assert audit.rounding(bare, 1.0) == 0.0


def test_the_system_shall_hold_the_stored_residual_to_its_terms_within_the_rounding_of_n_term_sums():
    """The identity balance_residual = ΔE + D + j − W − W_Γ holds up to ``IDENTITY_REL`` plus the run's rounding
    allowance (N ε grows with the unknowns), and a residual off by more is reported."""
    e = np.array([0.0, 1.0e-3, 1.3e-3])
    a = {"external_work": np.array([0.0, 1.0e-3, 3.0e-4]), "boundary_work": np.zeros(3), "stored_energy": e,
         "friction_dissipation": np.zeros(3), "euler_dissipation": np.zeros(3), "balance_residual": np.zeros(3)}
    allowance = 2e-11
    for off, reported in ((0.5 * allowance, False), (2.0 * (audit.IDENTITY_REL + allowance), True)):
        a["balance_residual"] = np.array([0.0, 0.0, off * 1.3e-3])
        found = [m for m in audit.problems(a, allowance) if "differs" in m]
        assert bool(found) == reported, (off, found)

"""Hostile inputs of issue 43 §3: forged energy audits in results files, each reported by
scripts/check_results.py, whether the forger left the step checksums as they were (they cover the audit) or
recomputed them (the audit's terms are recomputed from the stored fields: tresca_py.audit_evidence)."""
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from tresca_py import checksum, results
from tresca_py.common import CASES, ROOT


@pytest.fixture(scope="module")
def example(tmp_path_factory, rust_bin):
    """Example 5.1 in 8 steps: contact that slips, a clamped side without data (so every term is recomputed)."""
    out = tmp_path_factory.mktemp("forged") / "example.h5"
    subprocess.run([rust_bin, "run", f"{CASES}/paper_example_5_1.toml", "--steps", "8", "-q", "-o", str(out)],
                   check=True, capture_output=True)
    return out


def copy(example, tmp_path):
    bad = tmp_path / example.name  # the sidecar names its results file
    shutil.copy(example, bad)
    shutil.copy(example.with_suffix(".xdmf"), bad.with_suffix(".xdmf"))
    return bad


def check_results(path):
    return subprocess.run([sys.executable, f"{ROOT}/scripts/check_results.py", str(path)], capture_output=True,
                          text=True)


def rechecksum(path, audit=True):
    """What a forger who knows XXH64 does: every step's checksum recomputed, with the audit (or, for a file made to
    look older, without it and without the attribute saying it is covered)."""
    with h5py.File(path, "r+") as f:
        ds = f["tresca/steps/checksum"]
        if not audit:
            del ds.attrs[checksum.COVERS]
    r = results.read(str(path), verify=False)
    with h5py.File(path, "r+") as f:
        f["tresca/steps/checksum"][: r.completed] = r.checksums()


def forge(path, forgery):
    with h5py.File(path, "r+") as f:
        g = f["tresca/steps"]
        names = [k.removeprefix("steps/") for k in checksum.AUDIT]
        if forgery in ("times 2", "times 1e6"):
            for k in names:
                g[k][...] = float(forgery.split()[1]) * g[k][()]
        elif forgery == "zeroed":
            for k in names:
                g[k][...] = 0.0
        elif forgery == "deleted":
            for k in names:
                del g[k]
        elif forgery == "energy shifted, work compensated":
            # Eⁿ + δn and (lⁿ, δuⁿ) + δ: ΔE + D + j − W − W_Γ, and so the balance, unchanged
            d = 0.1 * float(np.max(g["stored_energy"][()]))
            n = np.arange(len(g["stored_energy"]))
            g["stored_energy"][...] = g["stored_energy"][()] + d * n
            g["external_work"][...] = g["external_work"][()] + d * (n > 0)
        elif forgery == "work moved to the boundary":
            # W + W_Γ unchanged: the balance holds, the stored and dissipated energies are the true ones
            d = 0.5 * float(np.max(np.abs(g["external_work"][()])))
            g["external_work"][1:] = g["external_work"][1:] + d
            g["boundary_work"][1:] = g["boundary_work"][1:] - d
        else:
            j, e = g["friction_dissipation"][()], g["euler_dissipation"][()]
            g["friction_dissipation"][...], g["euler_dissipation"][...] = e, j


FORGERIES = ["times 2", "times 1e6", "zeroed", "deleted", "energy shifted, work compensated",
             "dissipations swapped", "work moved to the boundary"]


@pytest.mark.parametrize("forgery", FORGERIES)
def test_the_system_shall_report_a_forged_audit_by_its_checksums(example, tmp_path, forgery):
    bad = copy(example, tmp_path)
    forge(bad, forgery)
    r = check_results(bad)
    assert r.returncode != 0 and "OK" not in r.stdout, f"{forgery}: {r.stdout}{r.stderr}"
    assert "checksum" in r.stderr, f"{forgery}: {r.stderr}"


@pytest.mark.parametrize("forgery", FORGERIES)
def test_the_system_shall_report_a_forged_audit_whose_checksums_were_recomputed(example, tmp_path, forgery):
    bad = copy(example, tmp_path)
    forge(bad, forgery)
    rechecksum(bad, audit=forgery != "deleted")
    r = check_results(bad)
    assert r.returncode == 1 and "OK" not in r.stdout, f"{forgery}: {r.stdout}{r.stderr}"
    assert "energy audit" in r.stdout, f"{forgery}: {r.stdout}"


def test_the_system_shall_check_an_audit_its_checksums_do_not_cover_and_say_so(example, tmp_path):
    """A file of a version before the checksums covered the audit: read, checked, said to be uncovered; its
    audit recomputed still (a doubled stored energy is found)."""
    old = copy(example, tmp_path)
    rechecksum(old, audit=False)
    r = check_results(old)
    assert r.returncode == 0 and "not covered by the step checksums" in r.stdout, r.stdout + r.stderr
    with h5py.File(old, "r+") as f:
        f["tresca/steps/stored_energy"][...] = 2 * f["tresca/steps/stored_energy"][()]
    r = check_results(old)
    assert r.returncode == 1 and "stored_energy" in r.stdout, r.stdout + r.stderr


def test_the_system_shall_find_the_audit_of_a_valid_run_equal_to_its_fields(example):
    r = check_results(example)
    assert r.returncode == 0 and "not recomputed" not in r.stdout, r.stdout + r.stderr


def test_the_system_shall_check_the_covered_audit_of_a_stopped_run(rust_bin, tmp_path):
    """A run that stops (Uzawa's iteration limit) is cut to its completed steps: its checksum, rewritten then,
    still covers the audit and says so."""
    out = tmp_path / "stopped.h5"
    p = subprocess.run([rust_bin, "run", f"{CASES}/mms_front.toml", "--solver", "uzawa", "-q", "-o", str(out)],
                       capture_output=True, text=True)
    assert p.returncode == 1 and "did not converge" in p.stderr, p.stderr
    assert results.read(str(out)).audit_checksummed
    r = check_results(out)
    assert r.returncode == 0 and "not covered" not in r.stdout, r.stdout + r.stderr


@pytest.mark.parametrize("name", ["floating_block", "floating_coulomb_block"])
def test_the_system_shall_check_a_unilateral_floating_run_and_its_contact_work(rust_bin, tmp_path, name):
    """The system shall find the audit and the views of a valid floating run with normal unknowns and no boundary
    data equal to its fields, every term recomputed (the work of the contact reaction −Σ Pⁿ δuⁿ·n, the Dirichlet
    edges counted with one normal unknown a Γ_C edge, σxx of a uniaxial state measured against the stress's size),
    and report its boundary work forged by moving the external work there, checksums recomputed."""
    out = tmp_path / f"{name}.h5"
    subprocess.run([rust_bin, "run", f"{CASES}/{name}.toml", "-q", "-o", str(out)], check=True, capture_output=True)
    r = check_results(out)
    assert r.returncode == 0 and "not recomputed" not in r.stdout, r.stdout + r.stderr
    forge(out, "work moved to the boundary")
    rechecksum(out)
    r = check_results(out)
    assert r.returncode == 1 and "boundary_work" in r.stdout, r.stdout + r.stderr

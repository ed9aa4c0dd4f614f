"""Boundary data in the serial Python re-implementations (docs/scene.md, keys `u` and `gap`; issue 30 §1):
an affine field with Dirichlet data and an imposed normal displacement is reproduced exactly, both codes agree
with the Rust solver on a manufactured case with data, and data that do not fit together are refused."""
import os

import h5py
import numpy as np
import pytest

from conftest import PY, SCRIPTS, run
from tresca_py.common import CASES, MPIRUN
from tresca_py.compare import compare_files
from tresca_py.mesh import build_mesh
from tresca_py.scene import SceneError, load_scene
from tresca_py.scene_data import check_boundary_data

# u = t (0.01 x + 0.02 y, -0.02 x + 0.03 y), E = 1, nu = 0.25 (lambda = mu = 0.4): eps = t diag(0.01, 0.03),
# sigma = t diag(0.024, 0.04), sigma_12 = 0, so on Gamma_C = {y = 0} (n = (0, -1)) with g_a = 0 it solves Tresca with
# u.n = -u_2(x, 0) = 0.02 t x; the top side carries the Dirichlet data u, the sides the traction sigma n.
PATCH = """
title = "affine patch with Dirichlet data and a gap"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [3, 3]
diagonal = "first"
refine = 0
[material]
E = 1.0
nu = 0.25
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0"
gap = "0.02*t*x"
[[boundary]]
name = "top"
kind = "dirichlet"
u = ["t*(0.01*x + 0.02*y)", "t*(-0.02*x + 0.03*y)"]
[[boundary]]
name = "right"
kind = "neumann"
traction = ["0.024*t", "0"]
[[boundary]]
name = "left"
kind = "neumann"
traction = ["-0.024*t", "0"]
[time]
T = 1.0
steps = 3
[exact]
u = ["t*(0.01*x + 0.02*y)", "t*(-0.02*x + 0.03*y)"]
grad = [["0.01*t", "0.02*t"], ["-0.02*t", "0.03*t"]]
"""

# an affine field's stored energy a_h(u,u) = int sigma:eps = t^2 (0.024*0.01 + 0.04*0.03) on the unit square
# (its jumps vanish, on Gamma_D too: u = u_D there)
PATCH_ENERGY = 0.00144

SOLVERS = ("skfem", "dolfinx")


@pytest.fixture(scope="module")
def patch(tmp_path_factory):
    d = tmp_path_factory.mktemp("bdata")
    path = d / "patch.toml"
    path.write_text(PATCH)
    return str(path)


def solve(solver, scene, out, *extra):
    p = run([PY, os.path.join(SCRIPTS, f"{solver}_solve.py"), scene, "-o", str(out), "-q", *extra])
    return p


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_system_shall_reproduce_an_affine_field_with_dirichlet_data_and_a_gap_exactly(solver, patch, tmp_path):
    """The discrete solution is the CR interpolant of the affine field (errors and energy at rounding); a lifting
    with the wrong sign, a missing b_D or an energy without the data terms would miss by O(1)."""
    out = tmp_path / "patch.h5"
    p = solve(solver, patch, out)
    assert p.returncode == 0, p.stderr
    with h5py.File(out, "r") as fh:
        g = fh["tresca"]
        t, u, energy = g["times"][()], g["u"][()], g["energy"][()]
        err = max(np.max(g["errors/energy"][()]), np.max(g["errors/h1"][()]), np.max(g["errors/l2"][()]))
        mid = g["mesh/midpoints"][()]
        slip = g["contact/slip"][()]
    unorm = np.max(np.abs(u))
    assert unorm > 0.01                      # the data move the body (u = 0.05 at the corner (1, 1), t = 1)
    # rounding of a few hundred operations on values of size |u| (cond(K) ~ 1e2 on this mesh)
    assert err < 1e-12 * unorm
    lin = np.stack([0.01 * mid[:, 0] + 0.02 * mid[:, 1], -0.02 * mid[:, 0] + 0.03 * mid[:, 1]], -1)   # (E, 2)
    assert np.max(np.abs(u - t[:, None, None] * lin[None])) < 1e-12 * unorm
    assert np.allclose(energy, PATCH_ENERGY * t ** 2, rtol=1e-10, atol=1e-16)
    assert np.max(np.abs(slip[-1])) > 0.005  # the tangential part moves: the friction step is exercised


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_system_shall_agree_with_rust_on_a_manufactured_case_with_boundary_data(solver, rust_bin, tmp_path):
    """mms_data_stop (Dirichlet data and a gap, a stick-slip front) at refine 0: DOF vectors, energies,
    tractions and true errors within 1e-8 (the cross-check's tolerance), identical stick/slip sets."""
    scene = os.path.join(CASES, "mms_data_stop.toml")
    rs, py = tmp_path / "rs.h5", tmp_path / f"{solver}.h5"
    p = run([rust_bin, "run", scene, "-o", str(rs), "-q", "--force", "--refine", "0"])
    assert p.returncode == 0, p.stderr
    p = solve(solver, scene, py, "--refine", "0")
    assert p.returncode == 0, p.stderr
    r = compare_files(str(rs), str(py))
    assert max(r["du"], r["dE"], r["dsig"], r["derr"]) <= 1e-8
    assert r["flags"] == 0


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_system_shall_refuse_an_initial_value_that_contradicts_the_dirichlet_data(solver, patch, tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text(PATCH + '[initial]\nu0 = ["0.001", "0"]\n')
    out = tmp_path / "bad.h5"
    p = solve(solver, str(scene), out)
    assert p.returncode == 2
    assert "inconsistent boundary data" in p.stderr and "Traceback" not in p.stderr
    assert not out.exists()


def _check(text, tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(text)
    scene = load_scene(str(path))
    mesh = build_mesh(scene)
    from tresca_py.skfem_cr.cr import Discretisation
    disc = Discretisation(scene, mesh)           # runs the check itself; here also directly
    b = np.flatnonzero(disc.is_boundary)
    check_boundary_data(scene, disc.points, disc.edges[b], disc.part_of_edge[b])


def test_the_system_shall_accept_consistent_boundary_data(tmp_path):
    _check(PATCH, tmp_path)


def test_the_system_shall_refuse_a_gap_that_contradicts_the_initial_normal_displacement(tmp_path):
    text = PATCH.replace('gap = "0.02*t*x"', 'gap = "0.02*t*x + 0.001"')
    with pytest.raises(SceneError, match=r"u0·n and part `bottom`'s gap"):
        _check(text, tmp_path)


def test_the_system_shall_accept_data_that_vanish_at_t0_up_to_rounding(tmp_path):
    """The gap's terms cancel at t0 = 0 ((0.1 + t)² − 0.01 − 0.2t − t² = 1.7e-18 there, 0 in exact arithmetic)
    while u0 = 0 and u_D(t0) = 0, so the relative tolerance alone is 0: accepted as Rust's
    tests/library/boundary_data.rs does; a mismatch of 1e-6 on the same data still refused."""
    gap = "0.02*t*x + (0.1 + t)*(0.1 + t) - 0.01 - 0.2*t - t*t"
    _check(PATCH.replace('gap = "0.02*t*x"', f'gap = "{gap}"'), tmp_path)
    with pytest.raises(SceneError, match=r"u0·n and part `bottom`'s gap"):
        _check(PATCH.replace('gap = "0.02*t*x"', f'gap = "{gap} + 1e-6"'), tmp_path)


def test_the_system_shall_refuse_data_that_disagree_at_a_shared_vertex(tmp_path):
    """The right side made a Dirichlet part whose data differ from the gap at the corner (1, 0) and from the top
    side's data at (1, 1) for t > 0 (they agree at t0 = 0, so only the vertex check can see it)."""
    text = PATCH.replace('name = "right"\nkind = "neumann"\ntraction = ["0.024*t", "0"]',
                         'name = "right"\nkind = "dirichlet"\nu = ["t*(0.01*x + 0.02*y)", "t*(-0.02*x + 0.03*y) + t"]')
    with pytest.raises(SceneError, match="common vertex"):
        _check(text, tmp_path)


def test_the_system_shall_read_zero_data_as_no_data_and_refuse_data_on_the_wrong_kind(tmp_path):
    path = tmp_path / "z.toml"
    path.write_text(
        PATCH.replace('gap = "0.02*t*x"', 'gap = "0"').replace(
            'u = ["t*(0.01*x + 0.02*y)", "t*(-0.02*x + 0.03*y)"]\n[[boundary]]', 'u = ["0", "0*x"]\n[[boundary]]', 1
        )
    )
    assert not load_scene(str(path)).has_boundary_data
    path.write_text(PATCH.replace('traction = ["0.024*t", "0"]', 'traction = ["0.024*t", "0"]\nu = ["0", "1"]'))
    with pytest.raises(SceneError, match="'u' is only allowed"):
        load_scene(str(path))


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_system_shall_check_the_python_solvers_results_files(solver, patch, tmp_path, capsys):
    """scripts/check_results.py accepts a file of the /tresca group alone (no views, no sidecar: the Python
    solvers' files) and still refuses one whose /tresca group is damaged."""
    from tresca_py import check
    out = tmp_path / "patch.h5"
    assert solve(solver, patch, out).returncode == 0
    assert check.main([str(out)]) == 0
    assert "the tresca group alone is checked" in capsys.readouterr().out
    with h5py.File(out, "r+") as fh:
        fh["tresca/u"][1, 0, 0] = np.nan
    assert check.main([str(out)]) == 2


@pytest.mark.mpi
def test_the_system_shall_apply_boundary_data_alike_in_dolfinx_serial_and_on_two_ranks(patch, tmp_path):
    """The data's load b_D and norm c(t) are assembled distributed and gathered: two ranks give the serial run
    to the cross-check's 1e-8 (the two differ by the summation order of the gathered entries)."""
    serial, par = tmp_path / "s.h5", tmp_path / "p.h5"
    assert solve("dolfinx", patch, serial).returncode == 0
    p = run([MPIRUN, "-n", "2", PY, os.path.join(SCRIPTS, "dolfinx_solve.py"), patch, "-o", str(par), "-q"])
    assert p.returncode == 0, p.stderr
    r = compare_files(str(serial), str(par))
    assert max(r["du"], r["dE"], r["dsig"], r["derr"]) <= 1e-8 and r["flags"] == 0


@pytest.mark.parametrize("solver", SOLVERS)
def test_the_system_shall_name_boundary_data_that_are_not_finite_at_a_step(solver, patch, tmp_path):
    """A gap consistent at t0 (exactly 0 there) but NaN from t = 1/2 on (sqrt of a negative number) stops the
    run at step 2 (t = 2/3) with one error line naming the expression, no traceback and no results file."""
    scene = tmp_path / "nan.toml"
    scene.write_text(PATCH.replace('gap = "0.02*t*x"', 'gap = "0.02*t*x + sqrt(0.25 - t*t) - 0.5"'))
    out = tmp_path / "nan.h5"
    p = solve(solver, str(scene), out)
    assert p.returncode == 2, p.stderr
    assert "gap" in p.stderr and "step 2" in p.stderr and "Traceback" not in p.stderr
    assert not out.exists()

"""The re-implementations of the discrete problem: scikit-fem, dolfinx (serial and mpirun -n 2) and the Rust
solver agree on small scenes; affine patch tests are exact; every stored step satisfies the discrete
variational inequality; the results file carries contact/mu and contact/dof."""
import h5py
import numpy as np
import pytest

from tresca_py.compare import compare_files
from tresca_py.mesh import match_points
from tresca_py.scene import load_scene
from tresca_py.skfem_cr.assemble import SkfemProblem
from tresca_py.skfem_cr.cr import Discretisation

# Agreement tolerance 1e-8: the three codes solve the same discrete problem with the same quadrature; the
# friction step is exact in each (active set / semismooth Newton to 1e-12), so they differ by rounding
# amplified by the condition number of K_r (~1e5 at these sizes): 1e-8 leaves a margin of ~100.
TOL = 1e-8
NAMES = ("patch_elastic_first", "patch_elastic_second", "patch_contact", "mms_elastic", "example51", "cyclic",
         "trapezoid")


def worst(a, b):
    r = compare_files(a, b)
    return max(r["du"], r["dE"], r["dsig"], r["derr"])


@pytest.mark.parametrize("name", NAMES)
def test_the_system_shall_give_the_same_solution_in_skfem_and_dolfinx(name, solve):
    assert worst(solve("skfem", name), solve("dolfinx", name)) <= TOL


@pytest.mark.parametrize("name", ("example51", "cyclic", "trapezoid", "patch_contact", "mms_elastic"))
def test_the_system_shall_give_the_same_solution_in_skfem_and_rust(name, solve):
    assert worst(solve("skfem", name), solve("rust", name)) <= TOL


@pytest.mark.mpi
@pytest.mark.parametrize("name", ("cyclic", "trapezoid", "mms_elastic"))
def test_the_system_shall_give_the_same_solution_in_dolfinx_serial_and_on_two_ranks(name, solve):
    assert worst(solve("dolfinx", name), solve("dolfinx", name, mpi=2)) <= TOL


@pytest.mark.parametrize("solver", ["skfem", "dolfinx"])
@pytest.mark.parametrize("name", ("patch_elastic_first", "patch_elastic_second", "patch_contact"))
def test_the_system_shall_reproduce_affine_fields_exactly(name, solver, solve):
    """The CR interpolant of an affine field is the discrete solution: every true error is rounding."""
    with h5py.File(solve(solver, name), "r") as fh:
        g = fh["tresca"]
        e = max(np.max(g["errors/energy"][()]), np.max(g["errors/h1"][()]), np.max(g["errors/l2"][()]))
        unorm = np.max(np.abs(g["u"][()]))
    assert e < 1e-12 * max(unorm, 1e-300)


@pytest.mark.parametrize("name", ("example51", "cyclic", "trapezoid", "patch_contact"))
def test_the_system_shall_satisfy_the_variational_inequality_at_every_stored_step(name, solve, scenes):
    """From the results file alone: K_r r = P^T l - B mu, |mu_e| <= w_e, mu_e = w_e sign(ds_e) where the
    contact unknown moved."""
    scene = load_scene(scenes[name])
    disc = Discretisation(scene)
    prob = SkfemProblem(disc)
    with h5py.File(solve("skfem", name), "r") as fh:
        g = fh["tresca"]
        U = g["u"][()].reshape(len(scene.times), -1)
        perm = match_points(disc.midpoints, g["mesh/midpoints"][()])
        mu_file = g["contact/mu"][()]
        cperm = match_points(disc.midpoints[disc.contact], g["mesh/midpoints"][()][g["contact/edges"][()]])
    Uc = np.zeros_like(U)
    for c in range(2):
        Uc[:, 2 * perm + c] = U[:, c::2]
    mu = np.zeros_like(mu_file)
    mu[:, cperm] = mu_file
    P, ic = disc.reduction()
    Kr = P.T @ prob.K @ P
    w = disc.weight
    for n in range(1, len(scene.times)):
        r = P.T @ Uc[n]
        assert np.max(np.abs(P @ r - Uc[n])) <= 1e-13 * max(1.0, np.abs(Uc[n]).max())   # constrained space
        load = P.T @ prob.load(scene.times[n])
        rhs = load.copy()
        rhs[ic] -= mu[n]
        # equilibrium to the direct solve's rounding (cond ~1e5, one refinement step)
        assert np.abs(Kr @ r - rhs).max() <= 1e-9 * max(np.abs(load).max(), 1e-300)
        if len(ic):
            assert np.max(np.abs(mu[n]) - w) <= 1e-12 * max(w.max(), 1e-300)
            ds = r[ic] - (P.T @ Uc[n - 1])[ic]
            moving = np.abs(ds) > 1e-10 * max(np.abs(Uc[n]).max(), np.abs(Uc[n - 1]).max())
            dev = np.abs(mu[n][moving] - w[moving] * np.sign(ds[moving]))
            assert np.max(dev, initial=0.0) <= 1e-9 * max(w.max(), 1e-300)


@pytest.mark.parametrize("solver", ["skfem", "dolfinx"])
def test_the_system_shall_write_the_friction_force_and_the_contact_unknown(solver, solve):
    with h5py.File(solve(solver, "cyclic"), "r") as fh:
        g = fh["tresca"]
        mu, sig, dof, slip = (g[f"contact/{k}"][()] for k in ("mu", "sigma_t", "dof", "slip"))
        pts, edges = g["mesh/points"][()], g["mesh/edges"][()][g["contact/edges"][()]]
    length = np.hypot(*(pts[edges[:, 1]] - pts[edges[:, 0]]).T)
    assert np.any(mu != 0)
    # sigma_t = -mu/|e| is written from mu: equal to one rounding
    assert np.max(np.abs(sig + mu / length)) <= 4e-16 * np.max(np.abs(sig))
    # the contact unknown s_e and u(m_e).tau_e differ by the rounding of u = P r (|tau| = 1)
    assert np.max(np.abs(dof - slip)) <= 1e-15 * max(np.max(np.abs(slip)), 1e-300)

"""The dolfinx re-implementation's unilateral Tresca contact (issue 40): the bound-constrained dual QP by PETSc TAO
with its active-set polish, the refusal of Coulomb friction, and the same-scheme agreement with tresca-cr and
scikit-fem (U9 of ``make verify``) at refine 0."""
import numpy as np

from tresca_py.common import PY, case, run
from tresca_py.skfem_cr.friction import bound_qp
from tresca_py.verify.cross_check import compare_pair, run_code


def test_the_system_shall_solve_the_bound_qp_with_tao_and_polish_it_to_the_exact_solution():
    """The system shall solve min ½xᵀCx − dᵀx over lo ≤ x ≤ hi (box, [0, ∞), free, pinned) by TAO TRON and the
    active-set polish to the exact solution: natural residual ≤ 1e-12 of the problem's scale, and within 1e-10 of
    the primal active-set solution (both exact on the same active set: they differ by the rounding of the
    C_FF solve, ≤ κ(C)·u·|x| with κ(C) ≤ ~1e5 here)."""
    from tresca_py.dolfinx_cr.friction import TaoBoundQP
    from tresca_py.dolfinx_cr.unilateral import natural_residual, polish
    rng = np.random.default_rng(40)
    for trial in range(100):
        n = int(rng.integers(2, 30))
        A = rng.standard_normal((n, n))
        C = A @ A.T + 1e-2 * np.eye(n)
        d = rng.standard_normal(n) * rng.uniform(0.1, 10)
        kind = rng.integers(0, 4, n)
        w = rng.uniform(0, 2, n)
        lo = np.select([kind == 0, kind == 1, kind == 2], [-w, 0.0, -np.inf], 0.0)
        hi = np.select([kind == 0, kind == 1, kind == 2], [w, np.inf, np.inf], 0.0)
        x, _ = TaoBoundQP(C, lo, hi).solve(d, rng.uniform(-2, 2, n) if trial % 2 else np.zeros(n))
        x, _ = polish(C, d, lo, hi, x)
        ref, _ = bound_qp(C, d, lo, hi, None)
        scale = np.abs(d).max() + np.abs(C).max() * max(np.abs(x).max(), 1.0)
        assert np.all(x >= lo) and np.all(x <= hi), trial
        assert natural_residual(C, d, lo, hi, x) <= 1e-12 * scale, trial
        assert np.max(np.abs(x - ref)) <= 1e-10 * max(1.0, np.max(np.abs(ref))), trial


def test_the_system_shall_refuse_coulomb_friction_in_the_dolfinx_solver(tmp_path):
    """The system shall refuse a Coulomb part in the dolfinx solver (TAO's bound-constrained QP is Tresca's),
    naming the reason, with exit status 2 and no results file."""
    out = tmp_path / "out.h5"
    p, _ = run([PY, "scripts/dolfinx_solve.py", case("mms_signorini_coulomb"), "-o", out, "-q"], check=False)
    assert p.returncode == 2 and "Tresca friction only" in p.stderr and "coulomb" in p.stderr
    assert not out.exists()


def agree(tmp_path, scene):
    """Run the three codes on ``scene`` at refine 0 and require every pair within 1e-8, 0 differing flags."""
    files = {}
    for code in ("rust", "skfem", "dolfinx"):
        files[code] = str(tmp_path / f"{code}.h5")
        ok, _, cmd, msg = run_code(code, scene, files[code], 0, None)
        assert ok, f"{cmd}: {msg}"
    for a, b in (("rust", "skfem"), ("rust", "dolfinx"), ("skfem", "dolfinx")):
        r, err = compare_pair(files[a], files[b])
        assert err is None, err
        assert max(r["du"], r["dE"], r["dsig"], r["derr"]) <= 1e-8 and r["flags"] == 0, (a, b, r)
    return r


def test_the_system_shall_agree_with_the_same_scheme_solvers_on_a_unilateral_scene(tmp_path):
    """The system shall solve mms_signorini_moving at refine 0 as tresca-cr, scikit-fem and dolfinx (TAO) do:
    every pair within 1e-8 in u, energies, tractions, pressures and true errors (κ(K_r)·κ(C)·u ≈ 1e-12 here,
    verify/same_scheme.py) with 0 differing stick/slip/separated flags."""
    assert agree(tmp_path, case("mms_signorini_moving"))["n_times"] == 9


def test_the_system_shall_agree_with_the_same_scheme_solvers_on_a_floating_body(tmp_path):
    """The system shall solve a floating body (no Dirichlet part: verify/same_scheme.py's block on a unilateral
    foundation and a symmetry plane) at refine 0 as tresca-cr, scikit-fem and dolfinx do (each with its own
    generalized inverse and the method of multipliers for the rigid motions): every pair within 1e-8, 0 differing
    flags (the equality Gᵀλ = e is met to 1e-14 of the force scale in the re-implementations, to the scene's
    tolerance 1e-12 in tresca-cr)."""
    from tresca_py.verify.same_scheme import FLOATING_SCENE
    scene = tmp_path / "floating.toml"
    scene.write_text(FLOATING_SCENE)
    assert agree(tmp_path, str(scene))["n_times"] == 5

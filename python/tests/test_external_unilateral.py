"""Smoke tests of the external codes' unilateral contact (issue 40 item 5) on tiny meshes: an affine patch that
is pressed onto the foundation and slips, through Signorini with Tresca and with Coulomb friction."""
import pytest

from tresca_py.external import problem, skfem_nitsche, suite
from tresca_py.external.skfem_signorini import SignoriniSolver

from test_external_solvers import G_A, PATCH

# u = t (0.01x + 0.02y, −0.01y): on y = 0, u·n = −u₂ = 0 = g (closed), σ_nn = σ₂₂ = −0.02μ (pressure 0.02μ =
# G_A > 0), σ_τ = −σ₁₂ = −0.02μ against the slip u_τ = 0.01x > 0. Tresca with g_a = G_A and Coulomb with F = 1
# (F p = G_A) both let the whole of Γ_C slip under exactly this traction: the step's solution is u.
PRESSED = (PATCH.replace('"t*0.01*y"', '"-t*0.01*y"').replace('["0", "0.01*t"]', '["0", "-0.01*t"]')
           .replace('kind = "contact"', 'kind = "contact"\nlaw = "unilateral"'))
LAWS = {"tresca": PRESSED, "coulomb": PRESSED.replace('g_a = "0.02/2.6"', 'coulomb = "1"')}


@pytest.fixture(params=sorted(LAWS))
def pressed(request, tmp_path):
    p = tmp_path / f"pressed_{request.param}.toml"
    p.write_text(LAWS[request.param])
    return p


def _check(raw):
    # P2 and P1 contain the affine field and the Nitsche terms are consistent: rounding errors only (1e-10
    # relative to |u|_H1 ≈ 0.025 leaves room for the Newton tolerance 1e-10)
    assert raw["err_h1_semi"] < 1e-10 and raw["err_l2"] < 1e-10, raw
    assert raw["sigma_t_integral"] == pytest.approx(-G_A, rel=1e-8)  # friction opposes the slip, |Γ_C| = 1
    assert raw["normal_force"] == pytest.approx(G_A, rel=1e-8)       # ∫ p = 0.02μ |Γ_C|
    assert raw["max_pressure"] == pytest.approx(G_A, rel=1e-8)
    assert raw["u_tau_points"] == pytest.approx([0.0025, 0.005, 0.0075], rel=1e-8)


def test_problem_reads_the_contact_law(pressed):
    """The system shall read a contact part's law, Coulomb coefficient and contact traction for the external
    codes, and refuse an unknown law naming the key."""
    part = next(p for p in problem.load(pressed)["parts"] if p["kind"] == "contact")
    assert part["law"] == "unilateral" and (part["coulomb"] is not None) == ("coulomb" in pressed.name)
    assert part["contact_traction"] is None
    bad = pressed.with_name("bad.toml")
    bad.write_text(pressed.read_text().replace('law = "unilateral"', 'law = "sticky"'))
    with pytest.raises(problem.ProblemError, match=r"boundary\[3\]\.law"):
        problem.load(bad)


def test_skfem_signorini_patch(pressed):
    """The system shall reproduce an affine field pressed onto the foundation that slips under the exact
    Tresca and Coulomb tractions (scikit-fem P2 Nitsche, Signorini)."""
    prob = problem.build(pressed, 0, degree=2)
    assert suite.unilateral(prob)
    _check(skfem_nitsche.solve(prob, SignoriniSolver))


@pytest.mark.skipif(not suite.getfem_available(), reason="GetFEM not installed under /usr/bin/python3 (make getfem)")
@pytest.mark.parametrize("degree", [1, 2])
def test_getfem_signorini_patch(pressed, tmp_path, degree):
    """The system shall reproduce the pressed, slipping affine field with GetFEM P1 and P2
    (Coulomb_friction_coupled_projection, Tresca as f = [0, g_a, g_a] and Coulomb as f = F)."""
    prob = problem.build(pressed, 0, degree=degree)
    prob["mixed"] = False
    _check(suite.run_getfem(prob, tmp_path))

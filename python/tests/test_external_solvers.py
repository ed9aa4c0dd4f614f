"""Smoke tests of the external codes (issue 30 §3) on tiny meshes: a patch test through the friction law."""
import json
import math
import subprocess

import pytest

from tresca_py.external import problem, quantities, richardson, skfem_mixed, skfem_nitsche, suite

# An affine field u = (0.01x + 0.02y, 0.01y) on the unit square: f = 0, u·n = 0 on y = 0, and on y = 0
# σ_τ = −σ₁₂ = −0.02μ while u_τ = 0.01x > 0: with g_a = 0.02μ the bottom slips everywhere under the exact
# Tresca traction. Dirichlet data t·u on the other sides, one step from u0 = 0: the step's solution is u.
PATCH = """
title = "affine patch through the friction law"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [2, 2]
[material]
E = 1.0
nu = 0.3
{dirichlet}
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0.02/2.6"
[time]
T = 1.0
steps = 1
[exact]
u = ["t*(0.01*x+0.02*y)", "t*0.01*y"]
grad = [["0.01*t", "0.02*t"], ["0", "0.01*t"]]
""".replace("{dirichlet}", "\n".join(
    f'[[boundary]]\nname = "{side}"\nkind = "dirichlet"\nu = ["t*(0.01*x+0.02*y)", "t*0.01*y"]'
    for side in ("right", "top", "left")))
G_A = 0.02 / 2.6


@pytest.fixture
def patch(tmp_path):
    p = tmp_path / "patch.toml"
    p.write_text(PATCH)
    return p


def _check_patch(raw):
    # Both discretisations contain the affine field and the Nitsche terms are consistent: the errors are
    # rounding (1e-9 relative to |u|_H1 ≈ 0.025 leaves room for the Newton tolerance 1e-10).
    assert raw["err_h1_semi"] < 1e-10 and raw["err_l2"] < 1e-10, raw
    # ∫ σ_τ over Γ_C = −g_a·|Γ_C|: the friction force opposes the slip (a tangent τ = n would give 0 here)
    assert raw["sigma_t_integral"] == pytest.approx(-G_A, rel=1e-8)
    assert raw["u_tau_points"] == pytest.approx([0.0025, 0.005, 0.0075], rel=1e-8)
    assert sum(raw["quad_stick"]) == 0  # slips everywhere


def test_skfem_nitsche_patch(patch):
    """The system shall reproduce an affine field that slips under the exact Tresca traction (scikit-fem P2)."""
    _check_patch(skfem_nitsche.solve(problem.build(patch, 0, degree=2)))


def test_skfem_mixed_patch(patch):
    """The system shall reproduce the affine slipping field with the Taylor–Hood P2/P1 Nitsche solver (the
    pressure −λ div u is constant, in P1)."""
    _check_patch(skfem_nitsche.solve(problem.build(patch, 0, degree=2), skfem_mixed.MixedSolver))


@pytest.mark.skipif(not suite.getfem_available(), reason="GetFEM not installed under /usr/bin/python3 (make getfem)")
@pytest.mark.parametrize("degree,mixed", [(1, False), (2, False), (2, True)])
def test_getfem_patch(patch, tmp_path, degree, mixed):
    """The system shall reproduce the affine slipping field with GetFEM P1, P2 and Taylor–Hood P2/P1."""
    prob = problem.build(patch, 0, degree=degree)
    prob["mixed"] = mixed
    raw = suite.run_getfem(prob, tmp_path)
    assert raw["code"] == ("getfem-TH" if mixed else f"getfem-P{degree}")
    _check_patch(raw)


def test_getfem_reports_bad_input(tmp_path):
    """The GetFEM entry point shall refuse a wrong command line with a message and a non-zero exit."""
    if not suite.getfem_available():
        pytest.skip("GetFEM not installed")
    import importlib.util
    script = importlib.util.find_spec("tresca_py.external.getfem_solver").origin
    proc = subprocess.run([suite.GETFEM_PYTHON, script], capture_output=True, text=True)
    assert proc.returncode == 2 and "usage" in proc.stderr
    missing = tmp_path / "missing.json"
    proc = subprocess.run([suite.GETFEM_PYTHON, script, str(missing), str(tmp_path / "out.json")],
                          capture_output=True, text=True)
    assert proc.returncode == 2 and "cannot read the problem file" in proc.stderr and "Traceback" not in proc.stderr


def test_richardson_exact_on_a_power_law():
    """The system shall extrapolate Q(h) = 1 + h² exactly, with its band bounding the finest value's error."""
    h = [0.4, 0.2, 0.1]
    lim = richardson.limit(h, [1 + x * x for x in h], p_th=2)
    assert lim.extrapolated and lim.p == pytest.approx(2.0) and lim.value == pytest.approx(1.0, abs=1e-14)
    assert lim.gci >= 0.01 * 1.0 - 1e-15  # 1.25·|d₂|/3 = 0.0125 ≥ the finest error 0.01
    osc = richardson.limit(h, [1.0, 1.1, 1.05], p_th=1)
    # not monotone: no extrapolation, band 3·max(|d₁|, |d₂|)/(2¹ − 1) (the last difference alone measures a
    # crossing, not the distance to the limit)
    assert not osc.extrapolated and osc.value == 1.05 and osc.gci == pytest.approx(3 * 0.1)


def test_richardson_fourth_level_check():
    """The system shall extrapolate only when a fourth level confirms the three finest levels' order."""
    h = [0.8, 0.4, 0.2, 0.1]
    ok = richardson.limit(h, [1 + x * x for x in h], p_th=2)
    assert ok.extrapolated and ok.value == pytest.approx(1.0, abs=1e-14)
    # the three finest follow 1 + h² but the coarsest does not (error 0.05 at h = 0.8 instead of 0.64)
    bad = richardson.limit(h, [1.05] + [1 + x * x for x in h[1:]], p_th=2)
    assert not bad.extrapolated and bad.value == pytest.approx(1.01) and bad.gci == pytest.approx(3 * 0.12 / 3)


def test_stick_ends():
    """The system shall place the stick–slip transitions at the zeros of the interpolated ψ = η − |δu_τ|."""
    a, b = quantities.stick_ends([0.0, 0.1, 0.2, 0.3, 0.4], [2.0, 0.0, 0.0, -0.0, 4.0], 1.0)
    assert (a, b) == pytest.approx((0.05, 0.325))
    assert all(math.isnan(v) for v in quantities.stick_ends([0.0, 0.1], [0.5, 0.2], 1.0))
    assert quantities.slip_threshold([0.0, -2.0], 0.5, 1.0) == pytest.approx(0.25 * 2.0)


def test_problem_rejects_unknown_names(tmp_path):
    """The scene reader shall name the key of an expression with unknown names."""
    p = tmp_path / "bad.toml"
    p.write_text(PATCH.replace('g_a = "0.02/2.6"', 'g_a = "0.02*z"'))
    with pytest.raises(problem.ProblemError, match="g_a"):
        problem.build(p, 0)


def test_problem_is_json(patch):
    """The problem description shall be JSON-serialisable (it is the GetFEM subprocess's input)."""
    json.dumps(problem.build(patch, 1, degree=1))


def test_stick_ends_skip_dirichlet_junction():
    """The system shall not report as a stick zone the slip's vanishing within h of a Γ_C/Γ_D junction."""
    s = [0.05, 0.15, 0.25, 0.35, 0.45, 0.55, 0.65, 0.75, 0.85, 0.95]
    dslip = [1.0] * 9 + [1e-6]     # all slips; the slip → 0 at the clamped end s = 1
    raw = {"h1_norm": 1.0, "energy": 1.0, "sigma_t_integral": 0.0, "u_tau_points": [0.0, 0.0, 0.0],
           "u_tau_samples": [0.0], "quad_s": s, "quad_dslip": dslip, "dofs": 1, "wall_s": 0.0, "h": 0.1}
    probes = {"length": 1.0, "dirichlet_ends": [False, True]}
    row = quantities.summarise(raw, probes)
    assert math.isnan(row["stick_a"]) and math.isnan(row["stick_b"])
    probes["dirichlet_ends"] = [False, False]  # a Neumann end: the same data is a stick zone at the end
    row = quantities.summarise(raw, probes)
    assert row["stick_a"] == pytest.approx(0.85 + 0.1 * (0.01 - 1.0) / (0.01 - 1.0 - (0.01 - 1e-6)))


def gmsh_patch(tmp_path):
    """PATCH on the Gmsh pentagon of the suite (verification/external/scenes/gmsh_pentagon.msh, Γ_C = [0,1]×{0})."""
    from tresca_py.common import ROOT
    msh = f"{ROOT}/verification/external/scenes/gmsh_pentagon.msh"
    text = PATCH.replace('corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]\ncells = [2, 2]',
                         f'file = "{msh}"').replace('name = "bottom"', 'name = "contact"')
    p = tmp_path / "gmsh_patch.toml"
    p.write_text(text)
    return p


def test_gmsh_scene_is_read_and_red_refined(tmp_path):
    """The scene reader shall read a Gmsh scene (mesh.file) as tresca-cr does: 12·4^r triangles at level r,
    the contact part's segments oriented and chained from (0, 0) to (1, 0), a clear error for r < 0."""
    scene = problem.load(gmsh_patch(tmp_path))
    for r in (0, 2):
        prob = problem.at_level(scene, r, degree=1)
        assert len(prob["triangles"]) == 12 * 4 ** r
        segs = next(p["segments"] for p in prob["parts"] if p["kind"] == "contact")
        assert len(segs) == 2 * 2 ** r and all(a[1] == b[0] for a, b in zip(segs[:-1], segs[1:], strict=True))
        assert prob["probes"]["start"] == [0.0, 0.0] and prob["probes"]["tangent"] == pytest.approx([1.0, 0.0])
        assert prob["probes"]["length"] == pytest.approx(1.0)
    with pytest.raises(problem.ProblemError, match="coarsened"):
        problem.at_level(scene, -1)


def test_skfem_nitsche_patch_on_gmsh_mesh(tmp_path):
    """The system shall reproduce the affine slipping field on the red-refined Gmsh pentagon (scikit-fem P2)."""
    _check_patch(skfem_nitsche.solve(problem.build(gmsh_patch(tmp_path), 1, degree=2)))


def test_study_estimates_state_a_reason_instead_of_nan(tmp_path):
    """The system shall report tresca-cr study's output estimates from its CSV columns (elastic_energy, not
    a missing 'energy'): a limit ± GCI where extrapolated, else "not extrapolated: why", never NaN."""
    from tresca_py.external.report import study_estimates
    p = tmp_path / "study.csv"
    p.write_text("refine,elastic_energy_limit,elastic_energy_gci,elastic_energy_verdict,max_slip_limit,max_slip_gci,"
                 "max_slip_verdict\n3,5.8e-3,2.2e-6,in the asymptotic range,,,"
                 "\"not yet: refine further (the three finest values oscillate)\"\n")
    est = study_estimates(p)
    assert est["elastic_energy"] == "0.0058 ± 2.2e-06 (in the asymptotic range)"
    assert est["max_slip"] == "not extrapolated: the three finest values oscillate"
    assert est["stick_length"] == "not in the study's CSV"
    assert not any("nan" in v.lower() for v in est.values())

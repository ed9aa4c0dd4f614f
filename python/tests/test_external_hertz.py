"""The external suite's Hertz scene (issue 40 item 5): levels that are the Hertz study's new meshes, symmetry
parts and a curved contact side in the external codes, the pressure's width ``half_width``."""
import math
from pathlib import Path

import numpy as np
import pytest

from tresca_py.external import hertz, problem, quantities, skfem_nitsche, suite
from tresca_py.external.skfem_signorini import SignoriniSolver

ROOT = Path(__file__).resolve().parents[2]
BINARY = ROOT / "target" / "release" / "tresca-cr"
COMMITTED = ROOT / "verification" / "cases" / "hertz_a10.toml"

# u = t (0.01x, −0.01y) on the unit square: div u = 0, σ = 2μ ε(u) = diag(0.02μ, −0.02μ) t, σ₁₂ = 0. On x = 0
# u·n = −u₁ = 0 and σ_τ = 0: a symmetry part holds it (a free side would carry −σ₁₁ = −0.02μ ≠ 0, a clamped
# one u₂ ≠ 0). On y = 0 u·n = −u₂ = 0 = g (closed) under the pressure p = −σ₂₂ = 0.02μ = 0.02/2.6 and no shear:
# frictionless unilateral contact (g_a = 0) holds it. ∫p = p, ∫p x² = p/3, so half_width = 2/√3.
SYMMETRIC = """
title = "affine patch with a symmetry side, pressed frictionless onto the foundation"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [2, 2]
diagonal = "{diagonal}"
[material]
E = 1.0
nu = 0.3
[[boundary]]
name = "left"
kind = "symmetry"
[[boundary]]
name = "right"
kind = "dirichlet"
u = ["0.01*t*x", "-0.01*t*y"]
[[boundary]]
name = "top"
kind = "dirichlet"
u = ["0.01*t*x", "-0.01*t*y"]
[[boundary]]
name = "bottom"
kind = "contact"
law = "unilateral"
g_a = "0"
[time]
T = 1.0
steps = 1
[exact]
u = ["0.01*t*x", "-0.01*t*y"]
grad = [["0.01*t", "0"], ["0", "-0.01*t"]]
"""
P = 0.02 / 2.6


@pytest.fixture(params=["first", "second"])
def symmetric(request, tmp_path):
    p = tmp_path / "symmetric.toml"
    p.write_text(SYMMETRIC.replace("{diagonal}", request.param))
    return p


def _longest_edge(prob):
    pts, tri = np.asarray(prob["points"]), np.asarray(prob["triangles"])
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    return float(np.max(np.linalg.norm(pts[edges[:, 0]] - pts[edges[:, 1]], axis=1)))


def test_hertz_levels_are_the_study_meshes(tmp_path):
    """The system shall build the external Hertz scene's level L from the Hertz study's mesh level L with the
    committed δ load: level 0 is verification/cases/hertz_a10.{toml,msh} (the same mesh file, the same scene
    apart from its header and the mesh file's name), the nominal h halves from level to level, and the external
    reader sees the symmetry part and a curved contact side."""
    p0, h0 = hertz.level_scene("hertz_a10", tmp_path, 0)
    assert Path(p0).with_suffix(".msh").read_text() == COMMITTED.with_suffix(".msh").read_text()
    body = [ln for ln in COMMITTED.read_text().splitlines() if not ln.startswith("#")]
    assert Path(p0).read_text().replace("hertz_a10_l0.msh", "hertz_a10.msh").splitlines() == body
    p1, h1 = hertz.level_scene("hertz_a10", tmp_path, 1)
    assert h1 == h0 / 2
    prob = problem.at_level(problem.load(p1), 0)
    assert {p["name"]: p["kind"] for p in prob["parts"]} == {
        "axis": "symmetry", "top": "dirichlet", "free": "neumann", "contact": "contact"}
    assert prob["probes"]["curved"]
    # the meshes follow the nominal h: the longest edge halves too, to 10 %
    longest = [_longest_edge(problem.at_level(problem.load(p), 0)) for p in (p0, p1)]
    assert longest[0] / longest[1] == pytest.approx(h0 / h1, rel=0.1)
    assert not problem.build(ROOT / "verification" / "cases" / "mms_front.toml", 0)["probes"]["curved"]
    with pytest.raises(ValueError, match="no Hertz load 'hertz_a20'"):
        hertz.level_scene("hertz_a20", tmp_path, 0)


def test_hertz_is_a_mesh_level_scene():
    """The system shall run the Hertz scene on mesh levels with its own compared quantities (half_width among
    them, no tangential ones) and the P2 codes one level lower."""
    sc = next(s for s in suite.SCENES if s.name == "hertz")
    assert sc.mesh_levels is not None and len(sc.levels) >= 4
    assert quantities.HALF_WIDTH in sc.quantities and "u_tau_1" not in sc.quantities
    assert sc.levels_of("skfem-P2-nitsche") == tuple(r - 1 for r in sc.levels)


def _check(raw, prob):
    # P1, P2 and CR contain the affine field; the contact and symmetry terms are consistent: rounding errors
    # only (1e-10 relative to |u|_H1 ≈ 0.014 leaves room for the Newton tolerance 1e-10)
    assert raw["err_h1_semi"] < 1e-10 and raw["err_l2"] < 1e-10, raw
    assert raw["normal_force"] == pytest.approx(P, rel=1e-8)
    assert raw["max_pressure"] == pytest.approx(P, rel=1e-8)
    row = quantities.summarise(dict(raw, h=prob["h"]), prob["probes"])
    assert row[quantities.HALF_WIDTH] == pytest.approx(2 / math.sqrt(3), rel=1e-8)


def test_skfem_symmetry_patch(symmetric):
    """The system shall hold a symmetry part's normal displacement at 0 with no tangential traction in the
    scikit-fem P2 Signorini solver (an affine field that a free or a clamped side would not reproduce)."""
    prob = problem.build(symmetric, 0, degree=2)
    _check(skfem_nitsche.solve(prob, SignoriniSolver), prob)


@pytest.mark.skipif(not suite.getfem_available(), reason="GetFEM not installed under /usr/bin/python3 (make getfem)")
@pytest.mark.parametrize("degree", [1, 2])
def test_getfem_symmetry_patch(symmetric, tmp_path, degree):
    """The system shall impose a symmetry part in GetFEM P1 and P2 (a normal Dirichlet condition with
    multipliers) and reproduce the pressed affine field."""
    prob = problem.build(symmetric, 0, degree=degree)
    prob["mixed"] = False
    _check(suite.run_getfem(prob, tmp_path), prob)


@pytest.mark.skipif(not BINARY.exists(), reason="no release binary (cargo build --release)")
def test_tresca_symmetry_patch(symmetric, tmp_path):
    """The system shall read tresca-cr's pressure on the contact part only, not on a symmetry part's edges
    (which tresca-cr writes among its contact edges), and reproduce the pressed affine field."""
    prob = problem.build(symmetric, 0, degree=2)
    _check(suite.solve_level("tresca-cr", prob, tmp_path, BINARY, symmetric, 0, 1, "r0"), prob)


def test_skfem_refuses_a_slanted_symmetry_part(symmetric):
    """The system shall refuse, naming the part, a symmetry part that is not on a line x = const or y = const in
    the scikit-fem solver (its constraint is then no single dof's)."""
    text = symmetric.read_text().replace("[0.0, 1.0]]", "[-0.3, 1.0]]")
    symmetric.write_text(text)
    with pytest.raises(ValueError, match="symmetry part 'left'"):
        skfem_nitsche.solve(problem.build(symmetric, 0, degree=2), SignoriniSolver)

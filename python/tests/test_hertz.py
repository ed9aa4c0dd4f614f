"""Tests of tresca_py.hertz (issue 40 item 3): Hertz's formulas, the graded quarter-disc mesh and scene, the
extraction of a, p₀ and the profile errors, and the HZ requirements' verdicts. Fast: level 0 runs only."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from tresca_py.hertz import extract, formulas
from tresca_py.hertz.levels import LOADS, variant, write_level
from tresca_py.hertz.mesh import Grading, quarter_disc
from tresca_py.scene import load_scene
from tresca_py.verify import hertz as vh

E, NU, R = 1.0, 0.3, 1.0


def test_formulas_consistent():
    """The system shall compute Hertz's a and p₀ so that the profile integrates to P and a(P) inverts P(a)."""
    P = 0.0085
    a = formulas.half_width(P, R, E, NU)
    p0 = formulas.peak_pressure(P, a)
    x = np.linspace(-a, a, 200001)
    assert np.trapezoid(formulas.profile(x, a, p0), x) == pytest.approx(P, rel=1e-6)
    assert formulas.load_for(a / R, R, E, NU) == pytest.approx(P, rel=1e-14)
    assert a == pytest.approx(math.sqrt(4 * P * R * (1 - NU ** 2) / (math.pi * E)), rel=1e-15)
    with pytest.raises(ValueError, match="P > 0"):
        formulas.half_width(0.0, R, E, NU)


def test_edge_means_exact():
    """The system shall average the Hertz profile over a segment exactly, across the zone's end too."""
    a, p0 = 0.1, 2.0
    assert formulas.edge_means([0.0], [a], a, p0)[0] == pytest.approx(math.pi / 4 * p0, rel=1e-14)
    assert formulas.edge_means([-a], [2 * a], a, p0)[0] == pytest.approx(math.pi / 2 * p0 * a / (3 * a), rel=1e-14)
    assert formulas.edge_means([2 * a], [3 * a], a, p0)[0] == 0.0


def test_mesh_on_circle_and_parts():
    """The system shall mesh the quarter disc with every arc vertex on the circle, positive triangles, the four
    parts covering the boundary and the contact part ending at x_c."""
    g = Grading(h_c=0.025, d_c=0.2, x_c=0.3)
    pts, tri, seg, name = quarter_disc(R, g, 1)
    a = pts[tri]
    area = (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (a[:, 1, 1] - a[:, 0, 1]) * (a[:, 2, 0] - a[:, 0, 0])
    assert area.min() > 0 and area.sum() / 2 < math.pi / 4 and area.sum() / 2 > math.pi / 4 * 0.99
    arc = np.unique(seg[(name == "contact") | (name == "free")])
    assert np.max(np.abs(np.hypot(pts[arc, 0], pts[arc, 1] - R) - R)) < 1e-14
    assert set(name) == {"contact", "free", "axis", "top"}
    assert pts[seg[name == "contact"]][:, :, 0].max() <= 0.3 + 1e-12
    assert len(quarter_disc(R, g, 2)[1]) > 3.5 * len(tri)    # a level halves h everywhere


def test_scene_loads(tmp_path):
    """The system shall write a Hertz scene that the Python scene reader accepts, with its symmetry and unilateral
    parts (the displacement-driven form: the Python reader refuses floating bodies)."""
    path = write_level(str(tmp_path), variant(LOADS[0], P=None, delta=0.015), 0)
    sc = load_scene(path)
    kinds = {b.name: b.kind for b in sc.boundaries}
    assert kinds == {"axis": "contact", "top": "dirichlet", "free": "neumann", "contact": "contact"}   # symmetry:
    assert "law" in open(path).read().split('name = "contact"')[1]                     # a bilateral contact part


def synthetic(a, p0, n=40, span=2.0):
    """Results-like object: edges on the circle facing the plane, p_e the exact Hertz edge means, plus an
    axis edge (normal (−1, 0)) with a large pressure that must be ignored."""
    th = np.linspace(0, span * a / R, n + 1)
    pts = np.stack([R * np.sin(th), R - R * np.cos(th)], 1)
    pts = np.vstack([pts, [[0.0, 0.5]]])
    edges = np.array([[i, i + 1] for i in range(n)] + [[n + 1, 0]])
    d = pts[edges[:, 1]] - pts[edges[:, 0]]
    normal = np.stack([d[:, 1], -d[:, 0]], 1) / np.linalg.norm(d, axis=1)[:, None]
    normal[-1] = [-1.0, 0.0]
    p = np.append(formulas.edge_means(pts[edges[:-1, 0], 0], pts[edges[:-1, 1], 0], a, p0), 1e3)
    c = SimpleNamespace(edges=np.arange(n + 1), normal=normal, pressure=np.stack([0 * p, p]))
    u = np.zeros((2, len(edges), 2))
    return SimpleNamespace(mesh=SimpleNamespace(points=pts, edges=edges), require_contact=lambda why: c, path="x",
                           u=u)


def test_extract_exact_profile():
    """The system shall recover P, a and p₀ from an exact Hertz pressure (profile errors at rounding, a_moment
    to the midpoint rule's O(h²)) and ignore the symmetry axis."""
    P = 0.0085
    a = formulas.half_width(P, R, E, NU)
    p0 = formulas.peak_pressure(P, a)
    c = extract.check_results(synthetic(a, p0), R, E, NU)
    assert c.P == pytest.approx(P, rel=1e-12) and c.a == pytest.approx(a, rel=1e-12)
    assert c.linf < 1e-12 and c.l2 < 1e-12
    assert abs(c.a_moment / a - 1) < (c.h_c / a) ** 2
    assert a <= c.a_edge < a + c.h_c and c.edges == 21                 # 20 edges inside a, one across it
    assert c.p0_h == pytest.approx(p0, rel=(c.h_c / a) ** 2)


def test_extract_sees_a_wrong_profile():
    """The system shall report a profile error when the pressure is not Hertz's (here a zone 10 % too wide)."""
    P = 0.0085
    a = formulas.half_width(P, R, E, NU)
    c = extract.check_results(synthetic(1.1 * a, formulas.peak_pressure(P, 1.1 * a)), R, E, NU)
    assert c.l2 > 0.05 and c.a_moment / c.a - 1 > 0.05


def test_level0_run(tmp_path, rust_bin):
    """The system shall run level 0 of the a/R ≈ 0.1 load and find a, p₀ within the coarse mesh's error of Hertz."""
    from tresca_py.hertz.levels import run_level
    c, dofs, _ = run_level(str(tmp_path), LOADS[0], 0)
    assert 0.08 < c.a / R < 0.12 and dofs > 0
    dev = c.deviations()
    assert abs(dev[0]) < 0.1 and abs(dev[2]) < 0.1 and c.l2 < 0.2


def rows(devs, a_R=0.1):
    return [dict(level=k, h=0.025 * 2 ** -k, h_a=0.25 * 2 ** -k, a_R=a_R, P=LOADS[0].case.P,
                 delta=1 + 0.01 * 4 ** -k,
                 a_moment=0.1 * (1 + 0.02 * 4 ** -k), p0_h=1.0 + 1e-5 * (2 + (-1) ** k), dev_am=devs, dev_p0=devs,
                 l2=2 * devs) for k in range(5)]


def test_requirements_can_fail():
    """The system shall fail HZ2 when the deviation exceeds κ a/(2R) and HZ1 when the order is off."""
    ld = LOADS[0]
    assert vh.hz1(ld, rows(0.01))[0]
    assert vh.hz2(ld, rows(0.01))[0]
    assert not vh.hz2(ld, rows(0.03))[0]
    unbalanced = rows(0.01)
    unbalanced[2]["P"] *= 1 + 1e-6
    assert not vh.hz2(ld, unbalanced)[0]
    bad = rows(0.01)
    for k, r in enumerate(bad):
        r["delta"] = 1 + 0.01 * 2 ** -k                   # order 1, not 2
    assert not vh.hz1(ld, bad)[0]

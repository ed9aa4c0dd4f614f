"""Meshes (tresca_py.mesh): the structured quadrilateral's counts, orientation, diagonals and side names, and
the Gmsh reader with red refinement."""
import os

import numpy as np
import pytest

from tresca_py.common import CASES
from tresca_py.mesh import build_mesh, match_points, structured_mesh
from tresca_py.scene import load_scene
from tresca_py.skfem_cr.cr import Discretisation


def test_the_system_shall_build_the_structured_mesh_of_the_readme():
    m = structured_mesh([[0, 0], [2, 0], [2, 1], [0, 1]], 4, 3, "first")
    assert len(m.points) == 20 and len(m.triangles) == 24
    assert {k: len(v) for k, v in m.boundary_segments.items()} == {"bottom": 4, "right": 3, "top": 4, "left": 3}
    p = m.points
    d1, d2 = p[m.triangles[:, 1]] - p[m.triangles[:, 0]], p[m.triangles[:, 2]] - p[m.triangles[:, 0]]
    assert np.all(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] > 0)        # counter-clockwise
    # first diagonal of cell (0,0) joins p(0,0) and p(1,1) = vertices 0 and 6; second: p(1,0), p(0,1)
    assert {0, 6} <= set(m.triangles[0]) and {0, 6} <= set(m.triangles[1])
    m2 = structured_mesh([[0, 0], [2, 0], [2, 1], [0, 1]], 4, 3, "second")
    assert {1, 5} <= set(m2.triangles[0]) and {1, 5} <= set(m2.triangles[1])
    assert np.all(m.points[m.boundary_segments["right"][:, 0], 0] == 2.0)


def test_the_system_shall_refine_a_gmsh_mesh_red_keeping_area_and_parts():
    sc = load_scene(os.path.join(CASES, "trapezoid.toml"))
    sc.mesh["refine"] = 0
    g0 = build_mesh(sc)
    sc.mesh["refine"] = 2
    g2 = build_mesh(sc)
    d0, d2 = Discretisation(sc, g0), Discretisation(sc, g2)
    assert len(g2.triangles) == 16 * len(g0.triangles)
    assert len(d2.contact) == 4 * len(d0.contact)
    # the trapezoid has area 10; sums of 16x more triangle areas: rounding only
    assert abs(d0.areas.sum() - 10.0) < 1e-12 and abs(d2.areas.sum() - d0.areas.sum()) < 1e-12


def test_the_system_shall_match_points_between_numberings_and_refuse_strangers():
    rng = np.random.default_rng(3)
    ref = rng.random((50, 2))
    perm = rng.permutation(50)
    assert np.array_equal(match_points(ref, ref[perm]), perm)
    try:
        match_points(ref, ref[:3] + 1e-3)
    except ValueError as err:
        assert "no partner" in str(err)
    else:
        raise AssertionError("a point without partner was matched")


@pytest.mark.parametrize("case", ["trapezoid", "mms_rotated", "mms_data_front"])
def test_the_system_shall_build_the_same_edge_data_in_both_python_re_implementations(case):
    """skfem_cr.cr.Discretisation and dolfinx_cr.edges.CrEdges are written independently: the same edges (by
    midpoint), boundary parts, Γ_C normals, tangents and ḡ_e, and the same CR interpolant and lifting."""
    from tresca_py.dolfinx_cr.edges import CrEdges
    sc = load_scene(os.path.join(CASES, f"{case}.toml"))
    a, b = Discretisation(sc), CrEdges(sc)
    k = match_points(a.midpoints, b.midpoints)             # b's edge i is a's edge k[i]
    assert np.array_equal(np.sort(a.edges[k], axis=1), np.sort(b.edges, axis=1))
    assert np.array_equal(a.part_of_edge[k], b.part_of_edge)
    assert np.array_equal(np.sort(k[b.contact]), np.sort(a.contact))
    kc = match_points(a.midpoints[a.contact], b.midpoints[b.contact])
    for name in ("normal", "tangent", "gbar", "weight"):
        assert np.allclose(getattr(a, name)[kc], getattr(b, name), rtol=0, atol=1e-14), name
    ua, ub = a.interpolate(sc.u0, 0.0).reshape(-1, 2), b.interpolate(sc.u0, 0.0).reshape(-1, 2)
    assert np.allclose(ua[k], ub, rtol=0, atol=1e-14)
    Pa, _ = a.reduction()
    Pb, _ = b.reduction()
    assert Pa.shape == Pb.shape

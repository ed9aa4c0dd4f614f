"""tresca_py.bisection: newest-vertex bisection's minimum-angle bound, computed independently of the Rust
refinement (make verify's A5 compares every adapted level against it)."""
import numpy as np

from tresca_py import bisection


def test_right_isosceles_triangles_keep_45_degrees():
    """The system shall bound a structured mesh's right isosceles triangles by 45° (NVB on the hypotenuse
    reproduces them, similar, forever)."""
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    assert abs(bisection.descendant_bound(pts, tris) - 45.0) < 1e-12


def test_the_bound_lies_below_the_initial_angles_and_settles():
    """The system shall give a bound ≤ the initial mesh's minimum angle that no further generation lowers
    (the four similarity classes appear early)."""
    pts = np.array([[0.0, 0.0], [3.0, 0.0], [0.4, 1.0]])
    tris = np.array([[0, 1, 2]])
    b6 = bisection.descendant_bound(pts, tris)
    assert b6 <= bisection.min_angles(pts[tris]).min() + 1e-12
    assert abs(bisection.descendant_bound(pts, tris, generations=12) - b6) < 1e-12
    assert b6 < bisection.min_angles(pts[tris]).min()


def test_longest_edge_labelling_keeps_the_triangle():
    """The system shall put the vertex opposite the longest side first, keeping the cyclic order."""
    t = np.array([[[0.0, 0.0], [3.0, 0.0], [0.4, 1.0]]])
    lab = bisection.label_longest_edge(t)[0]
    assert np.allclose(lab[0], [0.4, 1.0]) and np.allclose(lab[1], [0.0, 0.0]) and np.allclose(lab[2], [3.0, 0.0])

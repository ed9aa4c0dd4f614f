"""The graded quarter disc of the Hertz case, written as a Gmsh 4.1 ASCII file (meshio).

The cylinder of radius R has its centre at (0, R) and touches the plane y = 0 at the origin; by symmetry only
x ≥ 0, y ≤ R is meshed. Boundary parts (1D physical groups): ``axis`` (x = 0), ``top`` (y = R, the cut through
the centre), ``contact`` (the arc for x ≤ x_c) and ``free`` (the rest of the arc). Every arc vertex lies on the
circle, so each level is a new polygon closer to it (no red refinement, whose new vertices would stay on the
coarse chords).

Mesh size at distance d from the origin: h(d) = s · min(h_max, h_c + grading · max(0, d − d_c)); the level's
scale s = 2^(−level) refines everything, so successive levels halve h everywhere. Points: the three sides walked
with that spacing, and rings |p| = ρ around the origin (ρ_{k+1} = ρ_k + h(ρ_k)) sampled with the same spacing,
kept ≥ h/2 inside; the triangulation is their Delaunay triangulation (the polygon is convex, so it is the hull).
"""
from dataclasses import dataclass

import meshio
import numpy as np
from scipy.spatial import Delaunay

#: physical tags of the boundary parts and of the body
TAGS = {"contact": 1, "free": 2, "axis": 3, "top": 4}
BODY = 10


@dataclass(frozen=True)
class Grading:
    """Mesh sizes relative to R: h_c in the contact zone |p| ≤ d_c, growing by ``grading`` per unit distance up
    to h_max; x_c is where the contact part of the arc ends."""
    h_c: float
    d_c: float
    x_c: float
    h_max: float = 0.125
    grading: float = 0.3


def size(d, g: Grading, R, scale):
    return scale * R * np.minimum(g.h_max, g.h_c + g.grading * np.maximum(0.0, d / R - g.d_c))


def walk(length, spacing):
    """Parameters 0 = s_0 < … < s_n = length with s_{k+1} − s_k ≈ spacing(s_k), the last gap spread evenly."""
    s = [0.0]
    while s[-1] < length:
        s.append(s[-1] + float(spacing(s[-1])))
    n = max(len(s) - 1, 1)
    s = np.array(s[:n + 1])
    return s * (length / s[-1])


def boundary_points(R, g, scale):
    """Counter-clockwise boundary polygon: arc from the origin to (R, R), top back to (0, R), axis down."""
    arc = walk(0.5 * np.pi * R, lambda s: size(2 * R * np.sin(s / (2 * R)), g, R, scale))
    p_arc = np.stack([R * np.sin(arc / R), R - R * np.cos(arc / R)], 1)
    top = walk(R, lambda s: size(np.hypot(R - s, R), g, R, scale))
    p_top = np.stack([R - top, np.full_like(top, R)], 1)
    axis = walk(R, lambda s: size(R - s, g, R, scale))
    p_axis = np.stack([np.zeros_like(axis), R - axis], 1)
    return np.vstack([p_arc[:-1], p_top[:-1], p_axis[:-1]])


def interior_points(R, g, scale):
    pts = []
    rho = float(size(0.0, g, R, scale))
    while rho < 2 * R:
        h = float(size(rho, g, R, scale))
        n = max(int(np.ceil(0.5 * np.pi * rho / h)), 1)
        beta = (np.arange(n) + 0.5) * (0.5 * np.pi / n)
        p = rho * np.stack([np.cos(beta), np.sin(beta)], 1)
        margin = 0.5 * size(np.hypot(p[:, 0], p[:, 1]), g, R, scale)
        inside = np.minimum.reduce([p[:, 0], R - p[:, 1], R - np.hypot(p[:, 0], p[:, 1] - R)])
        pts.append(p[inside > margin])
        rho += h
    return np.vstack(pts)


def triangulate(pts):
    tri = Delaunay(pts).simplices.astype(np.int64)
    a = pts[tri]
    d1, d2 = a[:, 1] - a[:, 0], a[:, 2] - a[:, 0]
    area = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    tri[area < 0] = tri[area < 0][:, [0, 2, 1]]
    return tri, np.abs(area) / 2


def classify(pts, nb, R, x_c):
    """The boundary segments (i, i+1) of the polygon of nb points and their part names."""
    i = np.arange(nb)
    seg = np.stack([i, (i + 1) % nb], 1)
    a, b = pts[seg[:, 0]], pts[seg[:, 1]]
    tol = 1e-12 * R
    name = np.where((np.abs(a[:, 0]) < tol) & (np.abs(b[:, 0]) < tol), "axis",
                    np.where((np.abs(a[:, 1] - R) < tol) & (np.abs(b[:, 1] - R) < tol), "top",
                             np.where(np.maximum(a[:, 0], b[:, 0]) <= x_c * R + tol, "contact", "free")))
    return seg, name


def quarter_disc(R, g: Grading, level):
    """(points, triangles, segments, segment names) of the graded quarter disc at ``level``."""
    scale = 0.5 ** level
    bnd = boundary_points(R, g, scale)
    pts = np.vstack([bnd, interior_points(R, g, scale)])
    tri, area = triangulate(pts)
    if area.min() <= 1e-14 * R * R:
        raise ValueError(f"degenerate triangle (area {area.min():.3e}) in the Hertz mesh at level {level}")
    seg, name = classify(pts, len(bnd), R, g.x_c)
    return pts, tri, seg, name


def write_msh(path, pts, tri, seg, name):
    """Gmsh 4.1 ASCII file with one 1D physical group per boundary part and the body as group ``body``."""
    blocks, phys = [], []
    for part, tag in TAGS.items():
        blocks.append(("line", seg[name == part]))
        phys.append(np.full(int(np.sum(name == part)), tag))
    blocks.append(("triangle", tri))
    phys.append(np.full(len(tri), BODY))
    nb = len(seg)
    dim_tags = np.tile([2, BODY], (len(pts), 1))
    dim_tags[:nb, 0] = 1
    dim_tags[seg[:, 0], 1] = [TAGS[str(n)] for n in name]
    field = {part: np.array([tag, 1]) for part, tag in TAGS.items()}
    field["body"] = np.array([BODY, 2])
    m = meshio.Mesh(np.hstack([pts, np.zeros((len(pts), 1))]), blocks,
                    cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                    point_data={"gmsh:dim_tags": dim_tags}, field_data=field)
    meshio.write(path, m, file_format="gmsh", binary=False)

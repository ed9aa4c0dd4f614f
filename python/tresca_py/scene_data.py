"""Boundary data that do not fit together are refused before anything is solved (as the Rust solver's
``src/fem/lifting/consistency.rs``; docs/scene.md, keys ``u`` and ``gap``):

* u₀ must equal u_D(·, t₀) on every Dirichlet edge (u_D = 0 where a part gives none),
* u₀·n must equal g_n(·, t₀) on every Γ_C edge (g_n = 0 where a part gives none),
* at a vertex shared by two Dirichlet parts their data must agree, and at a vertex shared by a Dirichlet
  and a contact part u_D·n_e = g_n (n_e the contact edge's outward normal), at every time node.

Values are compared at the 3-point Gauss points of the edges and at the shared vertices, with the tolerance
of ``src/fem/lifting/consistency.rs``, whose module doc states the rule once: the largest of ``REL_TOL`` of the
size of the data, ``ROUNDING_ULPS`` ulps of the size the data reach over the time grid and ``ROUNDING_SAFETY``
times the rounding bound of the two values compared (``tresca_py.rounding``, the rule of
``src/scene/expr/rounding.rs`` on the sympy tree), so data that cancel to zero at t₀ by rounding are accepted
here as there. The constants are the Rust ones (a test compares them).
Scenes without boundary data are not checked (u₀ is projected onto V_h there).

Each solver calls ``check_boundary_data`` with its own boundary edges; this module only reads the scene.
"""
import numpy as np

from tresca_py.quadrature import GAUSS3_S
from tresca_py.expr import ExprError
from tresca_py.scene import SceneError

#: relative tolerance of the comparisons, ulps of the data's size over time, and the factor on the rounding bound
#: of the values compared: ``src/fem/lifting/consistency.rs`` (its module doc and constants)
REL_TOL = 1e-9
ROUNDING_ULPS = 64.0
ROUNDING_SAFETY = 2.0


def _vec(u, x, y, t):
    """u_D (or zero without data) at points x, y: shape (2, ...)."""
    return np.zeros((2,) + np.shape(x)) if u is None else u(x, y, t)


def _scal(g, x, y, t):
    return np.zeros(np.shape(x)) if g is None else g(x, y, t)


def _vec_rounding(u, x, y, t):
    """The rounding bound of u_D (zero without data), shape (2, ...)."""
    return np.zeros((2,) + np.shape(x)) if u is None else u.rounding(x, y, t)


def _scal_rounding(g, x, y, t):
    return np.zeros(np.shape(x)) if g is None else g.rounding(x, y, t)


def _dot_rounding(u, r, n0, n1):
    """The rounding bound of u·n from the components' bounds ``r`` (``dot_rounding`` of consistency.rs)."""
    terms = np.abs(u[0] * n0) + np.abs(u[1] * n1)
    return r[0] * np.abs(n0) + r[1] * np.abs(n1) + 1.5 * np.finfo(float).eps * terms


def _edge_rows(scene, a, b, part):
    """(what, points (k, 2), first values, second values, their rounding bound) of the u₀ comparisons on the
    boundary edges."""
    t0 = scene.times[0]
    rows = []
    q = a[:, None, :] + GAUSS3_S[None, :, None] * (b - a)[:, None, :]          # (k, 3, 2)
    d = (b - a) / np.hypot(*(b - a).T)[:, None]
    normal = np.stack([d[:, 1], -d[:, 0]], 1)                                # outward: edges counter-clockwise
    for ip, bd in enumerate(scene.boundaries):
        sel = part == ip
        if not np.any(sel) or bd.kind == "neumann" or (not bd.has_data and scene.u0.is_zero):
            continue
        if bd.kind == "contact" and scene.normal_unknowns:      # the gap is a constraint there, not u0's value
            continue
        x, y = q[sel, :, 0], q[sel, :, 1]
        u0, r0 = scene.u0(x, y, t0), _vec_rounding(scene.u0, x, y, t0)
        if bd.kind == "dirichlet":
            ud, rd = _vec(bd.u, x, y, t0), _vec_rounding(bd.u, x, y, t0)
            for c in range(2):
                rows.append((f"initial.u0[{c}] and part `{bd.name}`'s u[{c}] at t0 = {t0}", q[sel], u0[c], ud[c],
                             r0[c] + rd[c]))
        else:
            n0, n1 = normal[sel, None, 0], normal[sel, None, 1]
            un = u0[0] * n0 + u0[1] * n1
            r = _dot_rounding(u0, r0, n0, n1) + _scal_rounding(bd.gap, x, y, t0)
            rows.append((f"initial.u0·n and part `{bd.name}`'s gap at t0 = {t0}", q[sel], un, _scal(bd.gap, x, y, t0),
                         r))
    return rows, normal


def _vertex_rows(scene, a_idx, b_idx, points, part, normal):
    """The comparisons at vertices shared by two parts, one of them with data, at every time node."""
    rows = []
    at = {}
    for e, (va, vb) in enumerate(zip(a_idx, b_idx, strict=True)):
        for v in (int(va), int(vb)):
            at.setdefault(v, []).append(e)
    for v, edges in sorted(at.items()):
        for i, ea in enumerate(edges):
            for eb in edges[i + 1:]:
                pa, pb = scene.boundaries[part[ea]], scene.boundaries[part[eb]]
                if part[ea] == part[eb] or not (pa.has_data or pb.has_data):
                    continue
                if pa.kind == "contact" and pb.kind == "dirichlet":
                    pa, pb, ea, eb = pb, pa, eb, ea
                x = points[v]
                what = f"parts `{pa.name}` and `{pb.name}` at their common vertex"
                for t in scene.times:
                    if pa.kind == pb.kind == "dirichlet":
                        va, vb = _vec(pa.u, x[0], x[1], t), _vec(pb.u, x[0], x[1], t)
                        r = _vec_rounding(pa.u, x[0], x[1], t) + _vec_rounding(pb.u, x[0], x[1], t)
                        rows += [(f"{what} (u[{c}], t = {t})", x[None, :], va[c], vb[c], r[c]) for c in range(2)]
                    elif pa.kind == "dirichlet" and pb.kind == "contact":
                        ud = _vec(pa.u, x[0], x[1], t)
                        r = _dot_rounding(ud, _vec_rounding(pa.u, x[0], x[1], t), *normal[eb])
                        rows.append((f"{what} (u·n against gap, t = {t})", x[None, :], ud @ normal[eb],
                                     _scal(pb.gap, x[0], x[1], t), r + _scal_rounding(pb.gap, x[0], x[1], t)))
    return rows


def _data_size(scene, points, boundary_edges, part):
    """The largest |u_D| component and |g_n| at the vertices of the parts with data, over every time node
    (a node where the data are not finite is skipped: the run names it at its step)."""
    size = 0.0
    for ip, bd in enumerate(scene.boundaries):
        v = np.unique(boundary_edges[part == ip])
        if not bd.has_data or v.size == 0:
            continue
        x, y = points[v, 0], points[v, 1]
        for t in scene.times:
            try:
                d = _vec(bd.u, x, y, t) if bd.kind == "dirichlet" else _scal(bd.gap, x, y, t)
            except (ExprError, SceneError):
                continue
            size = max(size, float(np.max(np.abs(d), where=np.isfinite(d), initial=0.0)))
    return size


def check_boundary_data(scene, points, boundary_edges, part, u0_max=None):
    """Raise ``SceneError`` naming the parts, the point and the two values where the boundary data of
    ``scene`` do not fit together (module docstring). ``boundary_edges`` (k, 2): the vertex indices of every
    boundary edge, counter-clockwise (the body on the left); ``part`` (k,): the index of its boundary part.
    ``u0_max``: the largest |u₀| at the mesh's vertices when ``points`` holds only some of them (a
    distributed mesh); by default taken over ``points``."""
    if not scene.has_boundary_data:
        return
    points = np.asarray(points, dtype=float)
    boundary_edges, part = np.asarray(boundary_edges), np.asarray(part)
    a, b = points[boundary_edges[:, 0]], points[boundary_edges[:, 1]]
    rows, normal = _edge_rows(scene, a, b, part)
    rows += _vertex_rows(scene, boundary_edges[:, 0], boundary_edges[:, 1], points, part, normal)
    if u0_max is None:
        u0_max = float(np.max(np.abs(scene.u0(points[:, 0], points[:, 1], scene.times[0])), initial=0.0))
    scale = max([u0_max]
                + [max(float(np.max(np.abs(r[2]), initial=0.0)), float(np.max(np.abs(r[3]), initial=0.0)))
                   for r in rows])
    tol = max(REL_TOL * scale, ROUNDING_ULPS * np.finfo(float).eps * _data_size(scene, points, boundary_edges, part))
    for what, xy, va, vb, r in rows:
        diff = np.abs(np.asarray(va) - np.asarray(vb)).reshape(-1)
        allowed = np.maximum(tol, ROUNDING_SAFETY * np.broadcast_to(r, np.shape(va)).reshape(-1))
        if diff.size and np.any(diff > allowed):
            k = int(np.argmax(diff > allowed))
            x = np.asarray(xy).reshape(-1, 2)[k]
            raise SceneError(f"inconsistent boundary data: {what} differ at ({x[0]:.6f}, {x[1]:.6f}): "
                             f"{np.ravel(va)[k]:e} against {np.ravel(vb)[k]:e} (tolerance {allowed[k]:.1e})")

"""Boundary data that do not fit together are refused before anything is solved, as the Rust solver refuses
them (src/fem/lifting/consistency.rs):

* u₀ must equal u_D(·, t₀) on every Dirichlet edge (u_D = 0 where a part gives none),
* u₀·n must equal g_n(·, t₀) on every Γ_C edge (g_n = 0 where a part gives none),
* at a vertex shared by two Dirichlet parts their data must agree, and at a vertex shared by a Dirichlet and
  a contact part u_D·n_e = g_n (n_e the contact edge's outward normal), at every time node.

Values are compared at the 3-point Gauss points of the edges and at the shared vertices; tolerance 1e-9 of the
size of the data (the largest |u₀| at a mesh vertex or value compared): consistent data differ only by the
rounding of their expressions, a real mismatch below 1e-9 of the data is far below what the discretisation
resolves. The owned Dirichlet and Γ_C edges of every rank (O(√n) of them) are gathered to rank 0, which
compares; the verdict goes to every rank.
"""
import numpy as np
from mpi4py import MPI

from tresca_py.dolfinx_cr.distributed.data import evaluate
from tresca_py.dolfinx_cr.distributed.mesh import agree
from tresca_py.errors import InputError
from tresca_py.quadrature import GAUSS3_S

REL_TOL = 1e-9


def check(prob, data, A, B, pb):
    """Collective: Fail on every rank naming the first mismatch (module doc). ``data``: per part (u_D, g_n),
    ``A``, ``B``: the owned edges' end points, ``pb``: their boundary parts (-1 inside)."""
    comm, scene = prob.comm, prob.scene
    kind = np.array([b.kind for b in scene.boundaries] + ["interior"])[pb]
    sel = np.flatnonzero((kind == "dirichlet") | (kind == "contact"))
    normal = np.zeros((len(pb), 2))
    normal[prob.con_lb] = prob.normal
    parts = comm.gather((A[sel], B[sel], prob.edges_vertices[sel], pb[sel], normal[sel]), root=0)
    msg, scale = None, 0.0
    try:
        pts = prob.points
        scale = float(np.max(np.abs(evaluate(scene.u0, pts[:, 0], pts[:, 1], scene.times[0])), initial=0.0))
    except InputError as e:
        msg = str(e)
    agree(comm, msg)
    scale = comm.allreduce(scale, op=MPI.MAX)
    if comm.rank == 0:
        a, b, ev, part, nrm = (np.concatenate([p[k] for p in parts]) for k in range(5))
        try:
            rows = edge_rows(scene, data, a, b, part, nrm) + vertex_rows(scene, data, a, b, ev, part, nrm)
            msg = first_mismatch(rows, scale)
        except InputError as e:
            msg = str(e)
    agree(comm, msg)


def edge_rows(scene, data, a, b, part, nrm):
    """(what, points (k, 2), first values (k,), second values (k,)) of the u₀ comparisons on the edges."""
    t0 = float(scene.times[0])
    rows = []
    q = a[:, None, :] + GAUSS3_S[None, :, None] * (b - a)[:, None, :]              # (k, 3, 2)
    for ip, (bd, (u, g)) in enumerate(zip(scene.boundaries, data, strict=True)):
        sel = part == ip
        if not np.any(sel):
            continue
        x, y = q[sel, :, 0], q[sel, :, 1]
        u0 = evaluate(scene.u0, x, y, t0)
        pts = q[sel].reshape(-1, 2)
        if bd.kind == "dirichlet":
            ud = evaluate(u, x, y, t0) if u is not None else np.zeros_like(u0)
            rows += [(f"initial.u0[{c}] and part `{bd.name}`'s u[{c}] at t0 = {t0}", pts, u0[c].ravel(),
                      ud[c].ravel()) for c in range(2)]
        elif bd.kind == "contact":
            un = u0[0] * nrm[sel, 0, None] + u0[1] * nrm[sel, 1, None]
            gv = evaluate(g, x, y, t0) if g is not None else np.zeros_like(un)
            rows.append((f"initial.u0·n and part `{bd.name}`'s gap at t0 = {t0}", pts, un.ravel(), gv.ravel()))
    return rows


def vertex_rows(scene, data, a, b, ev, part, nrm):
    """The comparisons at vertices shared by two parts, one of them with data, at every time node."""
    at = {}
    for i in range(len(part)):
        for j in range(2):
            at.setdefault(int(ev[i, j]), []).append((i, (a, b)[j][i]))
    bnd, times = scene.boundaries, scene.times
    rows = []
    for edges in at.values():
        for n, (i, x) in enumerate(edges):
            for k, _ in edges[n + 1:]:
                pa, pk = part[i], part[k]
                if pa == pk or (data[pa] == (None, None) and data[pk] == (None, None)):
                    continue
                what = f"parts `{bnd[pa].name}` and `{bnd[pk].name}` at their common vertex"
                for t in times:
                    rows += pair_rows(what, bnd[pa].kind, bnd[pk].kind, data[pa], data[pk], x, float(t), nrm[i], nrm[k])
    return rows


def pair_rows(what, ka, kb, da, db, x, t, na, nb):
    """The comparison(s) of two parts' data at point x and time t (Dirichlet-Dirichlet, Dirichlet-contact)."""
    vec = lambda u: evaluate(u, x[0], x[1], t) if u is not None else np.zeros(2)  # noqa: E731
    gap = lambda g: float(evaluate(g, x[0], x[1], t)) if g is not None else 0.0  # noqa: E731
    p = x[None, :]
    if ka == kb == "dirichlet":
        va, vb = vec(da[0]), vec(db[0])
        return [(f"{what} (u[{c}], t = {t})", p, np.atleast_1d(va[c]), np.atleast_1d(vb[c])) for c in range(2)]
    if ka == "dirichlet" and kb == "contact":
        return [(f"{what} (u·n against gap, t = {t})", p, np.atleast_1d(vec(da[0]) @ nb), np.atleast_1d(gap(db[1])))]
    if ka == "contact" and kb == "dirichlet":
        return [(f"{what} (gap against u·n, t = {t})", p, np.atleast_1d(gap(da[1])), np.atleast_1d(vec(db[0]) @ na))]
    return []


def first_mismatch(rows, scale):
    """The message of the first comparison that differs by more than the tolerance, or None."""
    for _, _, va, vb in rows:
        scale = max(scale, float(np.max(np.abs(va), initial=0.0)), float(np.max(np.abs(vb), initial=0.0)))
    tol = REL_TOL * scale
    for what, pts, va, vb in rows:
        bad = np.flatnonzero(np.abs(va - vb) > tol)
        if len(bad):
            k = bad[0]
            return (f"inconsistent boundary data: {what} differ at ({pts[k, 0]:.6f}, {pts[k, 1]:.6f}): "
                    f"{va[k]:e} against {vb[k]:e} (tolerance {tol:.1e})")
    return None

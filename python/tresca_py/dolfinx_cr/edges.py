"""The dolfinx re-implementation's own Crouzeix-Raviart edge data (shares no code with the scikit-fem one):
the edge table, the boundary part of each edge, the Γ_C normals, tangents and friction weights, the CR
interpolant, the lifting of the boundary data and the reduction u = P r to the constrained space.

Edges are the nonzeros of the strictly upper triangle of the vertex adjacency matrix (scipy CSR, so sorted by
(low vertex, high vertex)); an edge seen by one triangle is a boundary edge and is stored in that triangle's
counter-clockwise orientation (the body on its left: outward normal n = (d_y, -d_x), tangent τ = d).
Unknowns: two per edge midpoint, ordered 2e + c; the constrained space has u = 0 at Dirichlet midpoints and
u = s_e τ_e at Γ_C ones (one unknown s_e each, listed last in r).
"""
import numpy as np
import scipy.sparse as sp

from tresca_py.mesh import build_mesh
from tresca_py.quadrature import GAUSS3_S, GAUSS3_W
from tresca_py.scene import SceneError
from tresca_py.scene_data import check_boundary_data


def _edge_table(points, tri):
    """(edges (E, 2) low-high, the triangle count per edge, tri_edge (T, 3): edge of side (v_k, v_k+1))."""
    nv = len(points)
    a = tri.ravel()
    b = np.roll(tri, -1, axis=1).ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    adj = sp.csr_matrix((np.ones(len(lo), dtype=np.int64), (lo, hi)), shape=(nv, nv))   # duplicates summed
    adj.sum_duplicates()
    adj.sort_indices()
    rows = np.repeat(np.arange(nv), np.diff(adj.indptr))
    edges = np.stack([rows, adj.indices], 1).astype(np.int64)
    count = adj.data
    numbering = sp.csr_matrix((np.arange(len(edges)), adj.indices, adj.indptr), shape=(nv, nv))
    tri_edge = np.asarray(numbering[lo, hi]).reshape(tri.shape).astype(np.int64)
    return edges, count, tri_edge


class CrEdges:
    """Edges, boundary parts, Γ_C data and the constrained space of a scene on its mesh (module docstring).

    Attributes: ``scene, points, triangles, edges, midpoints, lengths, is_boundary, part_of_edge`` (-1
    interior), ``dirichlet, contact, neumann`` (part name -> edges), ``normal, tangent, gbar, weight`` on Γ_C.
    """

    def __init__(self, scene, mesh=None):
        mesh = build_mesh(scene) if mesh is None else mesh
        self.scene, self.points, self.triangles = scene, mesh.points, mesh.triangles
        p, tri = self.points, self.triangles
        d1, d2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        if np.any(cross <= 1e-14 * np.max(np.abs(cross))):
            raise SceneError("mesh has degenerate or clockwise triangles (check the corner order)")
        edges, count, tri_edge = _edge_table(p, tri)
        if np.any(count > 2):
            raise SceneError("mesh is not a manifold: an edge is shared by more than two triangles")
        self.is_boundary = count == 1
        side_a, side_b = tri.ravel(), np.roll(tri, -1, axis=1).ravel()
        on_bnd = self.is_boundary[tri_edge.ravel()]
        edges[tri_edge.ravel()[on_bnd]] = np.stack([side_a[on_bnd], side_b[on_bnd]], 1)   # counter-clockwise
        self.edges = edges
        self.midpoints = 0.5 * (p[edges[:, 0]] + p[edges[:, 1]])
        d = p[edges[:, 1]] - p[edges[:, 0]]
        self.lengths = np.sqrt(np.einsum("ij,ij->i", d, d))
        self._mark_parts(mesh)
        c = self.contact
        self.tangent = d[c] / self.lengths[c, None]
        self.normal = np.column_stack([self.tangent[:, 1], -self.tangent[:, 0]])
        for b in scene.boundaries:
            if b.kind == "contact" and b.coulomb is not None:
                raise SceneError(f"boundary '{b.name}': the dolfinx solver models Tresca friction only (TAO's "
                                 "bound-constrained QP takes fixed thresholds, Coulomb's F·P moves with P): no coulomb")
        self.gbar = self._contact_means(lambda b, x, y: b.g_a(x, y, 0.0))
        self.normal_unknowns = scene.normal_unknowns
        part = self.part_of_edge[c]
        self.unilateral = np.array([scene.boundaries[ip].law == "unilateral" for ip in part], dtype=bool)
        if np.any(self.gbar < 0):
            raise SceneError("a contact part's g_a is negative somewhere")
        self.weight = self.lengths[c] * self.gbar
        bnd = np.flatnonzero(self.is_boundary)
        check_boundary_data(scene, p, edges[bnd], self.part_of_edge[bnd])

    def _mark_parts(self, mesh):
        """part_of_edge from the mesh's named boundary segments, every boundary edge in exactly one part."""
        names = [b.name for b in self.scene.boundaries]
        index = {tuple(e): k for k, e in enumerate(np.sort(self.edges, axis=1).tolist())}
        self.part_of_edge = np.full(len(self.edges), -1, dtype=np.int64)
        for ip, name in enumerate(names):
            if name not in mesh.boundary_segments:
                raise SceneError(f"boundary part '{name}' does not exist in the mesh "
                                 f"(available: {sorted(mesh.boundary_segments)})")
            for a, b in np.sort(mesh.boundary_segments[name], axis=1).tolist():
                k = index.get((a, b))
                if k is None or not self.is_boundary[k]:
                    raise SceneError(f"boundary part '{name}': segment ({a},{b}) is not a boundary edge of the mesh")
                if self.part_of_edge[k] >= 0:
                    raise SceneError(f"boundary edge at {self.midpoints[k]} belongs to both "
                                     f"'{names[self.part_of_edge[k]]}' and '{name}'")
                self.part_of_edge[k] = ip
        lost = np.flatnonzero(self.is_boundary & (self.part_of_edge < 0))
        if len(lost):
            raise SceneError(f"{len(lost)} boundary edge(s) belong to no [[boundary]] part, e.g. the edge with "
                             f"midpoint {self.midpoints[lost[0]].tolist()}")
        kind = np.array([b.kind for b in self.scene.boundaries] + ["interior"])[self.part_of_edge]
        self.dirichlet, self.contact = np.flatnonzero(kind == "dirichlet"), np.flatnonzero(kind == "contact")
        self.neumann = {b.name: np.flatnonzero(self.part_of_edge == ip)
                        for ip, b in enumerate(self.scene.boundaries) if b.kind == "neumann"}

    @property
    def n_dofs(self):
        return 2 * len(self.edges)

    def gauss3(self, edges):
        """The 3-point Gauss points of ``edges``: x, y of shape (len(edges), 3)."""
        a, b = self.points[self.edges[edges, 0]], self.points[self.edges[edges, 1]]
        xy = a[:, None, :] * (1.0 - GAUSS3_S)[None, :, None] + b[:, None, :] * GAUSS3_S[None, :, None]
        return xy[..., 0], xy[..., 1]

    def _contact_means(self, value):
        """Per Γ_C edge the 3-point Gauss mean of value(part, x, y)."""
        out = np.zeros(len(self.contact))
        for ip, b in enumerate(self.scene.boundaries):
            sel = self.part_of_edge[self.contact] == ip
            if b.kind == "contact" and np.any(sel):
                out[sel] = value(b, *self.gauss3(self.contact[sel])) @ GAUSS3_W
        return out

    def interpolate(self, vexpr, t):
        """I_CR v in the constrained space: edge means, zero on Γ_D, the tangential part on Γ_C."""
        mean = np.einsum("cep,p->ec", vexpr(*self.gauss3(np.arange(len(self.edges))), t), GAUSS3_W)
        mean[self.dirichlet] = 0.0
        if not self.normal_unknowns:
            s = np.einsum("ec,ec->e", mean[self.contact], self.tangent)
            mean[self.contact] = s[:, None] * self.tangent
        return mean.reshape(-1)

    def gap_means(self, t):
        """ḡ_e(t) of every Γ_C edge (zero without a gap)."""
        return self._contact_means(lambda b, x, y: np.zeros_like(x) if b.gap is None else b.gap(x, y, t))

    def lifting(self, t):
        """u_L(t): the edge means of u_D on Dirichlet edges with data, ḡ_e n_e on Γ_C edges with a gap, zero
        elsewhere (``tresca_py.dolfinx_cr.stepping``)."""
        u = np.zeros((len(self.edges), 2))
        for ip, b in enumerate(self.scene.boundaries):
            if b.kind == "dirichlet" and b.u is not None:
                e = self.dirichlet[self.part_of_edge[self.dirichlet] == ip]
                u[e] = np.einsum("cep,p->ec", b.u(*self.gauss3(e), t), GAUSS3_W)
        if not self.normal_unknowns:                 # with normal unknowns the gap is a constraint, not lifted
            u[self.contact] += self.gap_means(t)[:, None] * self.normal
        return u.reshape(-1)

    def reduction(self):
        """(P, contact positions in r): u = P r, two unknowns per free edge, then one s_e per Γ_C edge (and, with
        normal unknowns, then one r_e = u·n(m_e) per Γ_C edge: the midpoint value s_e τ_e + r_e n_e)."""
        ne = len(self.edges)
        constrained = np.zeros(ne, bool)
        constrained[self.dirichlet] = constrained[self.contact] = True
        free = np.flatnonzero(~constrained)
        nf, nc = 2 * len(free), len(self.contact)
        frames = [self.tangent] + ([self.normal] if self.normal_unknowns else [])
        rows = [np.column_stack([2 * free, 2 * free + 1]).ravel()]
        cols, vals = [np.arange(nf)], [np.ones(nf)]
        for k, f in enumerate(frames):
            rows += [2 * self.contact, 2 * self.contact + 1]
            cols += [nf + k * nc + np.arange(nc)] * 2
            vals += [f[:, 0], f[:, 1]]
        n = nf + len(frames) * nc
        P = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(2 * ne, n))
        return P.tocsr(), nf + np.arange(len(frames) * nc)

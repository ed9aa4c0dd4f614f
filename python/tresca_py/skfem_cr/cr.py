"""The Crouzeix-Raviart discretisation data of a scene on its mesh, framework independent: edges,
boundary parts, contact normals/tangents and friction weights, the CR interpolant and the reduction
u = P r to the constrained space (module docstring of ``tresca_py.skfem_cr``)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from tresca_py.expr import VecExpr
from tresca_py.mesh import Mesh, build_mesh
from tresca_py.quadrature import GAUSS3_S, GAUSS3_W
from tresca_py.scene import Scene, SceneError
from tresca_py.scene_data import check_boundary_data


class Discretisation:
    """Edges, boundary parts and contact data of a scene on its mesh (framework independent).

    Attributes: ``points, triangles, edges (E,2), midpoints, lengths, edge_tris (E,2; -1 = none),
    part_of_edge (E,; -1 interior)``, per kind the edge index arrays ``dirichlet, neumann (dict
    part -> edges), contact`` and for the contact edges ``normal, tangent, gbar, weight = |e| gbar``.
    Boundary edges are stored counter-clockwise (interior on the left), so tangent = direction.
    """

    def __init__(self, scene: Scene, mesh: Mesh | None = None):
        self.scene = scene
        mesh = build_mesh(scene) if mesh is None else mesh
        self.points, self.triangles = mesh.points, mesh.triangles
        self._edges()
        self._parts(mesh)
        self._contact_data()
        b = np.flatnonzero(self.is_boundary)
        check_boundary_data(scene, self.points, self.edges[b], self.part_of_edge[b])

    def _edges(self):
        """Edges (boundary ones counter-clockwise), their triangles, midpoints and lengths."""
        p, tri = self.points, self.triangles
        d1, d2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
        area2 = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        if np.any(area2 <= 1e-14 * np.max(np.abs(area2))):
            raise SceneError("mesh has degenerate or clockwise triangles (check the corner order)")
        self.areas = 0.5 * area2
        loc = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])   # oriented
        key = np.sort(loc, axis=1)
        edges, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        if np.any(cnt > 2):
            raise SceneError("mesh is not a manifold: an edge is shared by more than two triangles")
        nt = len(tri)
        self.tri_edges = inv.reshape(3, nt).T.copy()          # edge k = (v_k, v_{k+1})
        E = len(edges)
        bnd = cnt == 1
        edges[inv[bnd[inv]]] = loc[bnd[inv]]                   # boundary edges counter-clockwise
        self.edges = edges.astype(np.int64)
        self.edge_tris = -np.ones((E, 2), dtype=np.int64)
        owner = np.tile(np.arange(nt), 3)
        order = np.argsort(inv, kind="stable")
        first = np.ones(len(order), bool)
        first[1:] = inv[order][1:] != inv[order][:-1]
        self.edge_tris[inv[order][first], 0] = owner[order][first]
        self.edge_tris[inv[order][~first], 1] = owner[order][~first]
        self.midpoints = 0.5 * (p[self.edges[:, 0]] + p[self.edges[:, 1]])
        dvec = p[self.edges[:, 1]] - p[self.edges[:, 0]]
        self.lengths = np.hypot(dvec[:, 0], dvec[:, 1])
        self.is_boundary = bnd

    def _parts(self, mesh):
        """The boundary part of every edge, and the edge lists per kind."""
        scene, bnd, E = self.scene, self.is_boundary, len(self.edges)
        self.part_of_edge = -np.ones(E, dtype=np.int64)
        lookup = {(int(a), int(b)): k for k, (a, b) in enumerate(np.sort(self.edges, axis=1))}
        parts = {b.name: b for b in scene.boundaries}
        for name in parts:
            if name not in mesh.boundary_segments:
                avail = sorted(mesh.boundary_segments)
                raise SceneError(f"boundary part '{name}' does not exist in the mesh (available: {avail})")
        for ip, b in enumerate(scene.boundaries):
            segs = mesh.boundary_segments[b.name]
            for a, c in segs.tolist():
                k = lookup.get((min(a, c), max(a, c)))
                if k is None:
                    raise SceneError(f"boundary part '{b.name}': segment ({a},{c}) is not a mesh edge")
                if not bnd[k]:
                    raise SceneError(f"boundary part '{b.name}' contains an interior edge")
                if self.part_of_edge[k] >= 0:
                    other = scene.boundaries[self.part_of_edge[k]].name
                    raise SceneError(f"boundary edge at {self.midpoints[k]} belongs to both '{other}' and '{b.name}'")
                self.part_of_edge[k] = ip
        missing = np.flatnonzero(bnd & (self.part_of_edge < 0))
        if len(missing):
            unnamed = [n for n in mesh.boundary_segments if n not in parts]
            raise SceneError(f"{len(missing)} boundary edge(s) belong to no [[boundary]] part, e.g. the edge "
                             f"with midpoint {self.midpoints[missing[0]].tolist()} (undeclared mesh parts: {unnamed})")
        kinds = np.array([b.kind for b in scene.boundaries] + ["interior"])
        kind_of_edge = kinds[self.part_of_edge]
        self.dirichlet = np.flatnonzero(kind_of_edge == "dirichlet")
        self.contact = np.flatnonzero(kind_of_edge == "contact")
        self.neumann = {b.name: np.flatnonzero(self.part_of_edge == ip)
                        for ip, b in enumerate(scene.boundaries) if b.kind == "neumann"}
        self.interior = np.flatnonzero(~bnd)

    def _contact_data(self):
        """Normals, tangents and the edge means gbar of g_a (3-point Gauss) on the contact edges."""
        scene, p = self.scene, self.points
        dvec = p[self.edges[:, 1]] - p[self.edges[:, 0]]
        c = self.contact
        dv = dvec[c] / self.lengths[c, None]
        self.tangent = dv                                       # counter-clockwise direction
        self.normal = np.stack([dv[:, 1], -dv[:, 0]], 1)        # outward: tau = (-n_y, n_x)
        self.gbar = np.zeros(len(c))
        self.unilateral = np.zeros(len(c), bool)
        self.coulomb = np.full(len(c), np.nan)                  # F-bar_e on Coulomb edges, NaN on Tresca ones
        for ip, b in enumerate(scene.boundaries):
            if b.kind != "contact":
                continue
            sel = self.part_of_edge[c] == ip
            xq, yq = self.edge_points(c[sel])
            law, key = (b.g_a, "g_a") if b.coulomb is None else (b.coulomb, "coulomb")
            g = law(xq, yq, 0.0)
            if np.any(g < 0):                                   # (not finite: refused by the expression)
                bad = np.flatnonzero(g < 0)[0]
                raise SceneError(f"boundary '{b.name}': {key} = {g.flat[bad]:.6g} at ({xq.flat[bad]:.6g}, "
                                 f"{yq.flat[bad]:.6g}) is negative")
            if b.coulomb is None:
                self.gbar[sel] = g @ GAUSS3_W
            else:
                self.coulomb[sel] = g @ GAUSS3_W
            self.unilateral[sel] = b.law == "unilateral"
        self.weight = self.lengths[c] * self.gbar
        self.normal_unknowns = scene.normal_unknowns

    @property
    def n_dofs(self):
        return 2 * len(self.edges)

    def edge_points(self, edges):
        """3-point Gauss points on the given edges: x, y arrays of shape (len(edges), 3)."""
        a = self.points[self.edges[edges, 0]]
        b = self.points[self.edges[edges, 1]]
        q = a[:, None, :] + GAUSS3_S[None, :, None] * (b - a)[:, None, :]
        return q[..., 0], q[..., 1]

    def interpolate(self, vexpr: VecExpr, t=0.0):
        """CR interpolant (edge means, 3-point Gauss) in the constrained space, canonical ordering."""
        xq, yq = self.edge_points(np.arange(len(self.edges)))
        vals = vexpr(xq, yq, t) @ GAUSS3_W                      # (2, E)
        u = vals.T.copy()
        u[self.dirichlet] = 0.0
        if not self.normal_unknowns:                            # u.n = 0 (or the lifted gap) on Γ_C
            s = np.sum(u[self.contact] * self.tangent, axis=1)
            u[self.contact] = s[:, None] * self.tangent
        return u.ravel()

    def reduction(self):
        """Sparse P (2E x nred) with u_full = P r; the contact unknowns are the last entries of r: s_e (C of them),
        then, in a scene with normal unknowns, u_n(m_e) (C more). Returns (P, positions of the contact unknowns)."""
        E = len(self.edges)
        free = np.ones(E, bool)
        free[self.dirichlet] = False
        free[self.contact] = False
        fe = np.flatnonzero(free)
        nf = 2 * len(fe)
        C = len(self.contact)
        rows = np.concatenate([2 * fe, 2 * fe + 1, 2 * self.contact, 2 * self.contact + 1])
        cols = np.concatenate([2 * np.arange(len(fe)), 2 * np.arange(len(fe)) + 1,
                               nf + np.arange(C), nf + np.arange(C)])
        vals = np.concatenate([np.ones(nf), self.tangent[:, 0], self.tangent[:, 1]])
        nc = C
        if self.normal_unknowns:
            rows = np.concatenate([rows, 2 * self.contact, 2 * self.contact + 1])
            cols = np.concatenate([cols, nf + C + np.arange(C), nf + C + np.arange(C)])
            vals = np.concatenate([vals, self.normal[:, 0], self.normal[:, 1]])
            nc = 2 * C
        P = sp.csr_matrix((vals, (rows, cols)), shape=(2 * E, nf + nc))
        return P, nf + np.arange(nc)

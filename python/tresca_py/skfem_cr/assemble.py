"""Assembly of the discrete problem with scikit-fem (the scikit-fem re-implementation of tresca-cr).

The discrete problem (README, Problem 2 of Porwal & Wadhawan):

    a_h(u, v) = sum_T int_T sigma(u):eps(v) dx
              + sum_{e interior or Dirichlet} (2 rho mu / h_e) int_e [u].[v] ds      (2-point Gauss)
    (l^n, v)  = int_Omega f(t_n).v dx   (6-point Dunavant)  + int_{Gamma_N} g(t_n).v ds  (3-point Gauss)
    j_h(v)    = sum_{e in Gamma_C} |e| gbar_e |v_tau(m_e)|
    u^n = argmin_v 1/2 a_h(v,v) - (l^n, v) + j_h(v - u^{n-1})   (v = 0 on Gamma_D, v.n = 0 on Gamma_C)

sigma(u) = lambda tr eps(u) I + 2 mu eps(u) (plane strain).  Here scikit-fem assembles a_h with
``ElementVector(ElementTriCR())``: the elastic part with ``linear_elasticity``, the jump part with
``InteriorFacetBasis(side=0/1)`` pairs ([u] = u|T1 - u|T2) and a Dirichlet ``FacetBasis``; loads and
true errors are skfem forms with the fixed quadrature rules.  The friction step is solved exactly
on the condensed contact unknowns (``tresca_py.skfem_cr.friction``).
"""
import numpy as np
import scipy.sparse as sp
from skfem import (Basis, BilinearForm, ElementTriCR, ElementVector, FacetBasis, InteriorFacetBasis, LinearForm,
                   MeshTri, asm)
from skfem.helpers import dot
from skfem.models.elasticity import linear_elasticity

from tresca_py.quadrature import DUNAVANT_REF_W, DUNAVANT_REF_X
from tresca_py.skfem_cr.cr import Discretisation


class SkfemProblem:
    """Assembly of a_h, its jump part, loads and true errors with scikit-fem (canonical ordering)."""

    def __init__(self, disc: Discretisation):
        self.disc = disc
        scene = disc.scene
        self.lam, self.mu = scene.lam, scene.mu
        # sort_t=False keeps our counter-clockwise triangles and vertex numbering
        self.mesh = m = MeshTri(disc.points.T.copy(), disc.triangles.T.copy(), sort_t=False)
        self.elem = e = ElementVector(ElementTriCR())
        self.basis = Basis(m, e, quadrature=(DUNAVANT_REF_X, DUNAVANT_REF_W))
        # skfem facet f <-> canonical edge (match sorted vertex pairs)
        key = {tuple(p): k for k, p in enumerate(np.sort(disc.edges, axis=1).tolist())}
        self.edge_of_facet = np.array([key[tuple(p)] for p in np.sort(m.facets.T, axis=1).tolist()])
        self.facet_of_edge = np.empty_like(self.edge_of_facet)
        self.facet_of_edge[self.edge_of_facet] = np.arange(len(self.edge_of_facet))
        # canonical index of each skfem dof
        fd = self.basis.facet_dofs                      # (2, nfacets)
        self.canon = np.empty(self.basis.N, dtype=np.int64)
        self.canon[fd[0]] = 2 * self.edge_of_facet
        self.canon[fd[1]] = 2 * self.edge_of_facet + 1
        ok = np.allclose(self.basis.doflocs[:, fd[0]].T, disc.midpoints[self.edge_of_facet], atol=1e-12)
        assert ok, "CR dofs are not at the edge midpoints"

        rho, mu = scene.rho, self.mu

        @BilinearForm
        def penalty(u, v, w):
            return 2.0 * rho * mu / w.h * dot(u, v)

        K_el = asm(linear_elasticity(self.lam, self.mu), self.basis)
        self.fbs = fbs = [InteriorFacetBasis(m, e, side=i, intorder=3) for i in (0, 1)]
        self.fb_d = None
        J = sum((-1) ** (i + j) * asm(penalty, fbs[j], fbs[i]) for i in (0, 1) for j in (0, 1))
        if len(disc.dirichlet):
            self.fb_d = fb_d = FacetBasis(m, e, facets=self.facet_of_edge[disc.dirichlet], intorder=3)
            J = J + asm(penalty, fb_d)
        self.K = self._to_canonical(K_el + J)
        self.J = self._to_canonical(J)

        # loads
        self.neumann = []
        for ip, b in enumerate(scene.boundaries):
            if b.kind == "neumann" and not b.traction.is_zero:
                edges = disc.neumann[b.name]
                if len(edges):
                    self.neumann.append((b.traction, FacetBasis(m, e, facets=self.facet_of_edge[edges], intorder=5)))
            if b.kind == "contact" and b.traction is not None:        # the surface load on Γ_C, as a Neumann one
                edges = disc.contact[disc.part_of_edge[disc.contact] == ip]
                if len(edges):
                    self.neumann.append((b.traction, FacetBasis(m, e, facets=self.facet_of_edge[edges], intorder=5)))

    def _to_canonical(self, A):
        A = A.tocoo()
        n = self.disc.n_dofs
        return sp.csr_matrix((A.data, (self.canon[A.row], self.canon[A.col])), shape=(n, n))

    def _vec_to_canonical(self, b):
        out = np.zeros(self.disc.n_dofs)
        out[self.canon] = b
        return out

    def load(self, t):
        scene = self.disc.scene
        b = np.zeros(self.basis.N)

        def force(vexpr):
            @LinearForm
            def form(v, w):
                fx = vexpr(w.x[0], w.x[1], t)
                return fx[0] * v[0] + fx[1] * v[1]
            return form

        if not scene.f.is_zero:
            b += asm(force(scene.f), self.basis)
        for traction, fb in self.neumann:
            b += asm(force(traction), fb)
        return self._vec_to_canonical(b)

    def errors(self, t, u_canon):
        """(energy error^2, |u-u_h|_{1,h}^2, |u-u_h|_0^2); 6-point rule in T, 2-point Gauss on edges."""
        scene = self.disc.scene
        lam, mu = self.lam, self.mu
        uh = self.basis.interpolate(u_canon[self.canon])
        grad_ex = scene.exact_grad

        x = self.basis.global_coordinates()
        X, Y = x[0], x[1]                                   # (nel, nqp)
        G = np.array([[grad_ex[i][j](X, Y, t) for j in range(2)] for i in range(2)]) - uh.grad
        Eps = 0.5 * (G + np.swapaxes(G, 0, 1))
        tr = Eps[0, 0] + Eps[1, 1]
        el = lam * tr ** 2 + 2 * mu * np.einsum("ij...,ij...->...", Eps, Eps)
        h1 = np.einsum("ij...,ij...->...", G, G)
        d = scene.exact_u(X, Y, t) - uh.value
        l2 = d[0] ** 2 + d[1] ** 2
        dx = self.basis.dx                                  # quadrature weights * |det DF|
        jump = self.jump_energy(u_canon, t if scene.has_boundary_data else None)
        return float(np.sum(el * dx)) + jump, float(np.sum(h1 * dx)), float(np.sum(l2 * dx))

    def jump_energy(self, u_canon, t=None):
        """sum_{e interior or Dirichlet} (2 rho mu / h_e) int_e |[u_h]|^2 as a sum of squares (no cancellation);
        with a time t (a scene with boundary data) the jump of the error on a Dirichlet edge is u_h - u(t)."""
        scene = self.disc.scene
        usk = u_canon[self.canon]
        pen = lambda fb: 2.0 * scene.rho * self.mu / self.disc.lengths[self.edge_of_facet[fb.find]][:, None]  # noqa: E731
        d = self.fbs[0].interpolate(usk).value - self.fbs[1].interpolate(usk).value
        out = np.sum(np.sum(d ** 2, axis=0) * pen(self.fbs[0]) * self.fbs[0].dx)
        if self.fb_d is not None:
            d = self.fb_d.interpolate(usk).value
            if t is not None:
                xd = self.fb_d.global_coordinates()
                d = d - scene.exact_u(xd[0], xd[1], t)
            out += np.sum(np.sum(d ** 2, axis=0) * pen(self.fb_d) * self.fb_d.dx)
        return float(out)

"""Nonzero boundary data in the scikit-fem re-implementation: u = u_D(x, y, t) on a dirichlet part, u·n = g_n on a
contact part (docs/scene.md, keys ``u`` and ``gap``), the same discrete problem as the Rust solver's
``src/fem/lifting.rs``.

The displacement is uⁿ = wⁿ + u_Lⁿ with w in the constrained space (zero at Dirichlet midpoints, tangential at
Γ_C ones) and u_L the CR function with the edge means of the data at the midpoints of the data edges,

    u_L(m_e) = ū_D,e on a Dirichlet edge,   u_L(m_e) = ḡ_e n_e on a Γ_C edge,   zero elsewhere

(3-point Gauss means). The stabilisation's jump on a Dirichlet edge is measured against u_D, so step n
minimises ½a_h(u,u) − b_D(tₙ; u) + ½c(tₙ) − (lⁿ, u) + j_h(u − uⁿ⁻¹) over u = w + u_Lⁿ with

    b_D(t; v) = Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e u_D(·, t)·v,   c(t) = Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e |u_D(·, t)|²

(both by 3-point Gauss, scikit-fem ``FacetBasis`` with ``intorder=5``): w solves the friction step with the
load lⁿ + b_D(tₙ) − K u_Lⁿ. The energy written is 2Eⁿ = a_h(u,u) − 2b_D(u) + c, a_h with the Dirichlet jump
u − u_D. The friction problem is unchanged: u_L is normal to Γ_C.
"""
import numpy as np
from skfem import FacetBasis, Functional, LinearForm, asm

from tresca_py.quadrature import GAUSS3_W


def _data_load(ud, t, pen):
    """v -> (2ρμ/h_e) ∫_e u_D(t)·v on a facet basis."""
    @LinearForm
    def form(v, w):
        d = ud(w.x[0], w.x[1], t)
        return pen / w.h * (d[0] * v[0] + d[1] * v[1])
    return form


def _data_square(ud, t, pen):
    """(2ρμ/h_e) ∫_e |u_D(t)|² on a facet basis."""
    @Functional
    def form(w):
        d = ud(w.x[0], w.x[1], t)
        return pen / w.h * (d[0] ** 2 + d[1] ** 2)
    return form


class SkfemLifting:
    """The data's lifting u_L(t), b_D(t) and c(t) on a ``SkfemProblem`` (canonical ordering)."""

    def __init__(self, prob):
        self.prob = prob
        disc = prob.disc
        scene = disc.scene
        self.pen = 2.0 * scene.rho * prob.mu
        self.dirichlet = []                 # (u_D, edges, FacetBasis) per dirichlet part with data
        self.gap = []                       # (g_n, positions in disc.contact) per contact part with data
        for ip, b in enumerate(scene.boundaries):
            if b.kind == "dirichlet" and b.u is not None:
                edges = disc.dirichlet[disc.part_of_edge[disc.dirichlet] == ip]
                fb = FacetBasis(prob.mesh, prob.elem, facets=prob.facet_of_edge[edges], intorder=5)
                self.dirichlet.append((b.u, edges, fb))
            if b.kind == "contact" and b.gap is not None and not scene.normal_unknowns:
                self.gap.append((b.gap, np.flatnonzero(disc.part_of_edge[disc.contact] == ip)))

    def lift(self, t):
        """u_L(t): the edge means of u_D and ḡ_e n_e at the data edges' midpoints, zero elsewhere."""
        disc = self.prob.disc
        u = np.zeros((len(disc.edges), 2))
        for ud, edges, _ in self.dirichlet:
            xq, yq = disc.edge_points(edges)
            u[edges] = (ud(xq, yq, t) @ GAUSS3_W).T
        for g, pos in self.gap:
            edges = disc.contact[pos]
            xq, yq = disc.edge_points(edges)
            u[edges] = (g(xq, yq, t) @ GAUSS3_W)[:, None] * disc.normal[pos]
        return u.ravel()

    def rhs(self, t):
        """b_D(t; ·) in the canonical ordering."""
        b = np.zeros(self.prob.basis.N)
        for ud, _, fb in self.dirichlet:
            b += asm(_data_load(ud, t, self.pen), fb)
        return self.prob._vec_to_canonical(b)

    def data_norm(self, t):
        """c(t) = Σ_{Γ_D} (2ρμ/h_e) ∫_e |u_D(·, t)|²."""
        return float(sum(asm(_data_square(ud, t, self.pen), fb) for ud, _, fb in self.dirichlet))

    def energy(self, K, u, t):
        """2E = a_h(u,u) − 2b_D(t; u) + c(t): a_h with the Dirichlet jump measured against u_D."""
        return float(u @ (K @ u)) - 2.0 * float(self.rhs(t) @ u) + self.data_norm(t)


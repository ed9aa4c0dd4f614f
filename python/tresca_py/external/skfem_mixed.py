"""The scikit-fem Nitsche solver in mixed displacement–pressure form: Taylor–Hood P2/P1 (locking-free).

The bulk form a(u, v) = 2μ(ε(u), ε(v)) + λ(div u, div v) of ``skfem_nitsche`` becomes, with the pressure
p = −λ div u as an unknown in continuous P1,

    2μ(ε(u), ε(v)) − (p, div v) − (q, div u) − (p, q)/λ,      σ(u, p) = 2μ ε(u) − p I.

Taylor–Hood P2/P1 satisfies the discrete inf–sup condition uniformly in h (Brezzi–Fortin, Boffi–Brezzi–Fortin
§8.8, meshes with at least one interior vertex per triangle's vertices on the boundary, as on these structured
meshes), so its error bound ‖u − u_h‖_1 + ‖p − p_h‖_0 ≤ C h² (|u|_3 + |p|_2) has C independent of λ: no locking.
The contact terms are those of ``skfem_nitsche`` with the stress σ(u, p): the tangential traction τ·σ(u, p)n =
2μ τ·ε(u)n does not involve p (τ·n = 0), so the Tresca term acts on u only; the normal Nitsche term σ_n(u, p) =
2μ n·ε(u)n − p adds the couplings +∫_{Γ_C} p v_n and +∫_{Γ_C} q u_n (and the data term +∫ q g_n). Same
semismooth Newton, with the block matrix factored once.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import Basis, BilinearForm, ElementTriP1, FacetBasis, Functional, LinearForm, asm
from skfem.helpers import div
from skfem.models.elasticity import linear_elasticity

from .skfem_nitsche import Solver


class MixedSolver(Solver):
    """Taylor–Hood P2/P1: unknowns [u (P2²); p (P1)]; ``skfem_nitsche.Solver``'s time loop and Newton."""

    CODE = "skfem-TH-nitsche"

    def __init__(self, prob):
        super().__init__(prob)
        lam, mu, n = self.lam, self.mu, self.n
        self.lam_s = 0.0
        fac = self.parts[self.contact["name"]][1]
        self.pbasis = Basis(self.mesh, ElementTriP1(), intorder=6)
        self.fbp = FacetBasis(self.mesh, ElementTriP1(), facets=fac, intorder=6)
        self.ndof = self.nu + self.pbasis.N
        Kuu = asm(linear_elasticity(0.0, mu), self.basis)  # 2μ(ε(u), ε(v))
        B = asm(BilinearForm(lambda u, q, w: -div(u) * q), self.basis, self.pbasis)   # −(q, div u)
        C = asm(BilinearForm(lambda p, q, w: -p * q / lam), self.pbasis)                # −(p, q)/λ
        self.K = sp.bmat([[Kuu, B.T], [B, C]]).tocsr()
        An_uu = asm(BilinearForm(self._normal_form), self.fb)  # with lam_s = 0: σ = 2μ ε(u)
        # +∫ q u_n (test q, trial u) and its transpose +∫ p v_n
        Cn = asm(BilinearForm(lambda u, q, w: q * (u[0] * n[0] + u[1] * n[1])), self.fb, self.fbp)
        self.A_n = sp.bmat([[An_uu, Cn.T], [Cn, None]]).tocsr()
        self._qn_gap = lambda g: asm(LinearForm(lambda q, w: g * q), self.fbp)

    def gap_load_p(self, g):
        """+∫_{Γ_C} q g_n: the pressure rows of N(g_n n, ·) (σ_n(v, q) contains −q)."""
        return np.concatenate([np.zeros(self.nu), self._qn_gap(g)])

    def energy(self, x):
        """The mixed form's own energy ½(2μ‖ε(u)‖² + ‖p‖²/λ) (= ½a(u, u) when p = −λ div u)."""
        mu, lam, u = self.mu, self.lam, x[:self.nu]
        form = Functional(lambda w: mu * np.sum((0.5 * (w.u.grad + np.swapaxes(w.u.grad, 0, 1))) ** 2, axis=(0, 1)))
        pres = Functional(lambda w: 0.5 * w.p ** 2 / lam)
        return float(asm(form, self.basis, u=self.basis.interpolate(u))
                     + asm(pres, self.pbasis, p=self.pbasis.interpolate(x[self.nu:])))

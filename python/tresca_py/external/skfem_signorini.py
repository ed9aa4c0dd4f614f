"""The scikit-fem P2 Nitsche solver extended to Signorini: unilateral contact u·n ≤ g with Tresca or Coulomb
friction (Chouly–Hild–Renard Nitsche, θ = 0; Chouly, Hild & Renard, Math. Comp. 84 (2015), and Chouly,
ESAIM:M2AN 48 (2014) for Tresca).

On Γ_C the body carries σ(u)n = r + t_C (r the reaction of the foundation, t_C the scene's contact traction,
zero unless given). Each backward-Euler step solves, for u in P2 (nodal interpolant of u_D on Γ_D), for all v:

    a(u, v) − ∫_{Γ_C} [P_n(u)]₋ v_n − ∫_{Γ_C} proj_{[−s, s]}(P_τ(u)) v_τ = (lⁿ, v) + ∫_{Γ_C} t_C·v
    P_n(u) = r_n(u) − p (u_n − g),   P_τ(u) = r_τ(u) − p (u_τ − u_τⁿ⁻¹),   r(u) = σ(u)n − t_C
    [x]₋ = min(0, x),  s = g_a (Tresca, on all of Γ_C) or F·max(0, −P_n(u)) (Coulomb),  p = γ_N (λ + 2μ)/h_F

by semismooth Newton with the generalized derivative of both projections (for Coulomb also the threshold's
dependence on P_n on slipping points) and the base solver's backtracking line search on |R|; the Newton
matrix changes with the active sets and is factored in every iteration. The exact solution satisfies the
equation: [P_n(u)]₋ = r_n, the projected tangential part = r_τ. It imports nothing from tresca-cr's solvers.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla
from skfem import BilinearForm, Functional, LinearForm, asm

from .problem import evaluate
from .skfem_nitsche import NotConverged, Solver, _nsn


class SignoriniSolver(Solver):
    """:class:`Solver` with the unilateral contact law of the module docstring."""

    CODE = "skfem-P2-nitsche"

    def source(self, t):
        """(lⁿ, v) + ∫_{Γ_C} t_C·v."""
        rhs = super().source(t)
        tc = self.contact.get("contact_traction")
        if tc is not None:
            x = self.fb.global_coordinates().value
            tv = [evaluate(tc[c], x[0], x[1], t) for c in range(2)]
            rhs += asm(LinearForm(lambda v, w: tv[0] * v[0] + tv[1] * v[1]), self.fb)
        return rhs

    def load(self, t):
        return self.source(t)

    def augmented(self, u, u_prev, t):
        """(P_n, P_τ, the threshold s) at the contact quadrature points."""
        fu, fp = self.fb.interpolate(u), self.fb.interpolate(u_prev)
        n, tau, lam, mu = self.n, self.tau, self.lam, self.mu
        x = self.fb.global_coordinates().value
        rn, rt = _nsn(fu.grad, lam, mu, n, n), _nsn(fu.grad, lam, mu, tau, n)
        tc = self.contact.get("contact_traction")
        if tc is not None:
            tcx, tcy = (evaluate(tc[c], x[0], x[1], t) for c in range(2))
            rn, rt = rn - (tcx * n[0] + tcy * n[1]), rt - (tcx * tau[0] + tcy * tau[1])
        u_arr, du = np.asarray(fu), np.asarray(fu) - np.asarray(fp)
        g = evaluate(self.contact["gap"], x[0], x[1], t)
        pn = rn - self.pen * (u_arr[0] * n[0] + u_arr[1] * n[1] - g)
        pt = rt - self.pen * (du[0] * tau[0] + du[1] * tau[1])
        if self.contact.get("coulomb") is not None:
            s = evaluate(self.contact["coulomb"], x[0], x[1], t) * np.maximum(0.0, -pn)
        else:
            s = evaluate(self.contact["g_a"], x[0], x[1], t)
        return pn, pt, s

    def traction(self, u, u_prev, t):
        """(P_τ, the projected friction traction, s), as the base solver's quantities expect."""
        _, pt, s = self.augmented(u, u_prev, t)
        return pt, np.clip(pt, -s, s), s

    def residual(self, A, rhs, u, u_prev, t):
        """R(u) and the state (χ_n: in contact, χ_τ: sticking, P_τ's sign, the Coulomb coefficient or None)."""
        pn, pt, s = self.augmented(u, u_prev, t)
        n, tau = self.n, self.tau
        rn, rt = np.minimum(0.0, pn), np.clip(pt, -s, s)
        form = LinearForm(lambda v, w: rn * (v[0] * n[0] + v[1] * n[1]) + rt * (v[0] * tau[0] + v[1] * tau[1]))
        chi_n, chi_t = (pn < 0).astype(float), (np.abs(pt) < s).astype(float)
        return A @ u - rhs - asm(form, self.fb), (chi_n, chi_t, np.sign(pt))

    def jacobian(self, state, t):
        """K minus the generalized derivative of the contact terms at the state of :meth:`residual`."""
        chi_n, chi_t, sgn = state
        lam, mu, n, tau, pen = self.lam, self.mu, self.n, self.tau, self.pen
        coulomb = self.contact.get("coulomb")
        x = self.fb.global_coordinates().value
        fc = evaluate(coulomb, x[0], x[1], t) if coulomb is not None else 0.0

        def form(du, v, w):
            dpn = _nsn(du.grad, lam, mu, n, n) - pen * (du[0] * n[0] + du[1] * n[1])
            dpt = _nsn(du.grad, lam, mu, tau, n) - pen * (du[0] * tau[0] + du[1] * tau[1])
            vn, vt = v[0] * n[0] + v[1] * n[1], v[0] * tau[0] + v[1] * tau[1]
            dthr = -fc * chi_n * dpn  # d s / d u (Coulomb; zero for Tresca)
            return -chi_n * dpn * vn - (chi_t * dpt + (1 - chi_t) * sgn * dthr) * vt
        return self.K + asm(BilinearForm(form), self.fb)

    def step(self, u_prev, t, tol=1e-10, max_iter=60):
        """One backward-Euler step: semismooth Newton from u_prev, backtracking line search on |R|."""
        rhs = self.load(t)
        u = u_prev.copy()
        if self.D.size:
            u[self.D] = self.interpolate_dirichlet(t)[self.D]
        free = np.setdiff1d(np.arange(self.ndof), self.D)
        res, state = self.residual(self.K, rhs, u, u_prev, t)
        scale = max(np.linalg.norm(rhs), np.linalg.norm(res[free]), 1e-300)
        for it in range(1, max_iter + 1):
            rnorm = np.linalg.norm(res[free]) / scale
            if rnorm < tol:
                return u, it - 1, rnorm
            J = self.jacobian(state, t).tocsr()[free][:, free].tocsc()
            du = np.zeros_like(u)
            du[free] = spla.splu(J).solve(-res[free])
            u, res, state, _ = self.line_search(self.K, rhs, u, du, u_prev, t, rnorm, scale, free)
        raise NotConverged(f"skfem-signorini: step at t={t:g} did not converge in {max_iter} Newton iterations "
                           f"(relative residual {rnorm:.3e})")

    def quantities(self, u, u_prev, t):
        """The base quantities plus the total normal force ∫ −[P_n]₋, its moment ∫ −[P_n]₋ x² and the maximal
        pressure."""
        out = super().quantities(u, u_prev, t)
        pn, _, _ = self.augmented(u, u_prev, t)
        p = -np.minimum(0.0, pn)
        out["normal_force"] = float(asm(Functional(lambda w: p), self.fb))
        out["pressure_x2"] = float(asm(Functional(lambda w: p * w.x[0] ** 2), self.fb))
        out["max_pressure"] = float(np.max(p))
        return out

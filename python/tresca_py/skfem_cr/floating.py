"""The scikit-fem solver's step for a floating body (no Dirichlet part; ``tresca_py.floating``): K_# factorised once
by SuperLU in place of K_r, K⁺ = K_#⁻¹ with the pinned entries zeroed, and each step's contact problem with the
equilibrium Gᵀλ = e of the rigid motions by the method of multipliers around the exact solver of
``skfem_cr.unilateral``. Only scenes with normal unknowns (a unilateral or Coulomb part) float here."""
import numpy as np

from tresca_py.errors import InputError
from tresca_py.floating import kernel, multipliers, pin
from tresca_py.skfem_cr.unilateral import UnilateralStepSolver, solve_contact


class FloatingStepSolver(UnilateralStepSolver):
    """``UnilateralStepSolver`` of a floating body (module docstring)."""

    def __init__(self, disc, K):
        if not disc.normal_unknowns:
            raise InputError("[boundary] no dirichlet part: the re-implementations take a floating body with a "
                             "unilateral or Coulomb part only")
        P, ic = disc.reduction()
        self.R, self.pinned = kernel(P, disc.points, disc.midpoints, ic)
        super().__init__(disc, K)
        self.alpha = np.zeros(self.R.shape[1])

    def _factored(self, Kr):
        return pin(Kr, self.pinned)

    def _solve(self, b):
        b = np.array(b, dtype=float)
        b[self.pinned] = 0.0
        x = super()._solve(b)
        x[self.pinned] = 0.0
        return x

    def _contact(self, d, l_full):
        G, e = self.R[self.ic], self.R.T @ (self.P.T @ l_full)

        def inner(C, d, lam0):
            lam, its, _ = solve_contact(C, d, self.normal, lam0)
            return lam, its

        try:
            lam, self.alpha, its, eq = multipliers(inner, self.C, d, G, e, self.mu, self.alpha)
        except RuntimeError as err:
            raise InputError(str(err)) from None
        return lam, its, eq, self.R @ self.alpha

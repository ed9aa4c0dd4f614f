"""The per-step friction problem of backward Euler, solved exactly on the condensed contact unknowns
(module docstring of ``tresca_py.skfem_cr``): the box-constrained dual QP by a primal active-set
method, its KKT residual, the stick/slip classification and the step solver."""
import numpy as np
import scipy.sparse.linalg as spla

from tresca_py.skfem_cr.cr import Discretisation


def box_qp(C, d, w, mu0=None, max_iter=None):
    """Exact solution of min 1/2 mu^T C mu - mu^T d subject to |mu_i| <= w_i (C SPD, small, dense):
    ``bound_qp`` with the bounds -w, w. Returns (mu, iterations)."""
    return bound_qp(C, d, -w, w, mu0, max_iter)


def bound_qp(C, d, lo, hi, x0=None, max_iter=None):
    """Exact solution of min 1/2 x^T C x - x^T d subject to lo <= x <= hi (C SPD, small, dense; a bound may be
    infinite, lo_i = hi_i pins x_i).

    Primal active-set method: every iterate is feasible, a bound is dropped only at a minimiser of
    the current face, and the objective decreases strictly, so no face repeats (finite termination).
    Returns (x, iterations).
    """
    n = len(d)
    if n == 0:
        return np.zeros(0), 0
    max_iter = max_iter or 10 * n + 50
    mu = np.zeros(n) if x0 is None else np.clip(x0, lo, hi)
    upper = (mu >= hi)                     # fixed at the upper bound (lo == hi counts as fixed)
    lower = (mu <= lo) & ~upper
    fixed = upper | lower
    bounds = np.abs(np.concatenate([lo, hi]))
    bscale = np.max(bounds[np.isfinite(bounds)], initial=0.0)
    gscale = np.max(np.abs(d)) + np.max(np.abs(C)) * bscale + 1e-300
    for it in range(1, max_iter + 1):
        F = np.flatnonzero(~fixed)
        if len(F):
            rhs = d[F] - C[np.ix_(F, np.flatnonzero(fixed))] @ mu[fixed]
            target = np.linalg.solve(C[np.ix_(F, F)], rhs)
            p = target - mu[F]
            # ratio test against the box
            with np.errstate(divide="ignore", invalid="ignore"):
                lim = np.where(p > 0, (hi[F] - mu[F]) / p, np.where(p < 0, (lo[F] - mu[F]) / p, np.inf))
            j = int(np.argmin(lim)) if len(lim) else -1
            if j >= 0 and lim[j] < 1.0:
                alpha = max(lim[j], 0.0)
                mu[F] += alpha * p
                k = F[j]
                if p[j] > 0:
                    mu[k], upper[k] = hi[k], True
                else:
                    mu[k], lower[k] = lo[k], True
                fixed[k] = True
                continue
            mu[F] = target
        # multiplier (gradient) test on the fixed set
        g = C @ mu - d
        viol = np.zeros(n)
        viol[upper] = g[upper]              # at the upper bound optimal iff g <= 0
        viol[lower] = -g[lower]             # at the lower bound optimal iff g >= 0
        viol[lo >= hi] = 0.0                # lo == hi (w = 0): x is pinned
        k = int(np.argmax(viol))
        if viol[k] <= 1e-14 * gscale:
            return mu, it
        fixed[k] = upper[k] = lower[k] = False
    raise RuntimeError(f"box QP: no convergence in {max_iter} active-set iterations")


def kkt_residual(C, d, w, mu):
    """Natural residual |mu - P_box(mu - gamma (C mu - d))|_inf / max(w), gamma = 1/max diag C."""
    if len(mu) == 0:
        return 0.0
    return natural_residual(C, d, -w, w, mu) / max(np.max(w), 1e-300)


def natural_residual(C, d, lo, hi, x):
    """|x - P_[lo,hi](x - gamma (C x - d))|_inf, gamma = 1/max diag C: zero exactly at the QP's solution."""
    gamma = 1.0 / max(np.max(np.diag(C)), 1e-300)
    return float(np.max(np.abs(x - np.clip(x - gamma * (C @ x - d), lo, hi))))


class StepSolver:
    """Factorises K_r once and solves backward Euler steps exactly (see module docstring)."""

    def __init__(self, disc: Discretisation, K):
        self.disc = disc
        self.P, self.ic = disc.reduction()
        Kr = (self.P.T @ K @ self.P).tocsc()
        Kr = self._factored((0.5 * (Kr + Kr.T)).tocsc())
        self.Kr = Kr
        # K_r is SPD: symmetric minimum-degree ordering and diagonal pivots (SuperLU symmetric mode)
        self.lu = spla.splu(Kr, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                            options=dict(SymmetricMode=True))
        self.w = disc.weight
        C = len(self.ic)
        if C:
            B = np.zeros((Kr.shape[0], C))
            B[self.ic, np.arange(C)] = 1.0
            self.Z = self._solve(B)
            Cm = self.Z[self.ic, :]
            self.C = 0.5 * (Cm + Cm.T)
        else:
            self.Z = np.zeros((Kr.shape[0], 0))
            self.C = np.zeros((0, 0))
        self.mu = np.zeros(C)

    def _factored(self, Kr):
        """The matrix factorised for K_r (K_r itself; a floating body's K_#, ``skfem_cr.floating``)."""
        return Kr

    def _solve(self, b):
        x = self.lu.solve(b)
        x += self.lu.solve(b - self.Kr @ x)          # one step of iterative refinement
        return x

    def step(self, l_full, u_prev_full):
        """One backward Euler step; returns (u_full, info dict)."""
        disc = self.disc
        r_free = self._solve(self.P.T @ l_full)
        if len(self.ic) == 0:
            return self.P @ r_free, dict(iterations=1, residual=0.0, mu=np.zeros(0), d=np.zeros(0), ds=np.zeros(0),
                                         dof=np.zeros(0))
        s_old = np.sum(u_prev_full.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
        d = r_free[self.ic] - s_old
        mu, its = box_qp(self.C, d, self.w, self.mu)
        self.mu = mu.copy()
        r = r_free - self.Z @ mu
        u = self.P @ r
        return u, dict(iterations=its, residual=kkt_residual(self.C, d, self.w, mu), mu=mu, d=d,
                       ds=d - self.C @ mu, dof=r[self.ic])


def classify(mu, ds, d, w):
    """Stick (0) / slip (1) per contact edge, the convention of the Rust solver (friction::classify):
    slip when |mu_e| >= w_e (1 - 1e-9) and |ds_e| > 1e-9 max(|ds|_inf, |d|_inf), where ds = d - C mu is
    the slip increment of the step and d = s_free - s^{n-1} the increment without friction
    (w_e = 0: slip when |ds_e| exceeds the threshold)."""
    if len(mu) == 0:
        return np.zeros(0, dtype=bool)
    scale = max(float(np.max(np.abs(ds))), float(np.max(np.abs(d))))
    return (np.abs(mu) >= w * (1 - 1e-9)) & (np.abs(ds) > 1e-9 * scale)



"""The dolfinx re-implementation's step with normal unknowns (a unilateral part, issue 40; Tresca friction only):
every Γ_C edge e carries s_e and r_e = u·n(m_e) (``CrEdges.reduction``), the force on the body is −μ_e τ_e − P_e n_e
and, with B injecting both (tangential ones first), C = Bᵀ K_r⁻¹ B,

    d = (s_free − s^{n−1}, r_free − ḡ(tₙ)),   λ = (μ, P),   Δ = d − C λ = (Δs, r − ḡ),

a step solves the dual problem min ½λᵀCλ − dᵀλ over μ_e ∈ [−w_e, w_e], P_e ∈ [0, ∞) (unilateral) or (−∞, ∞)
(bilateral): PETSc TAO TRON with these bounds (``TaoBoundQP``), then the exact solution on its active set (the
polish below: TRON's projected-gradient test leaves λ within ~GATOL·scale·κ(C), which the 1e-8 agreement with
the exact solvers cannot afford on ill-conditioned scenes).

**Polish.** From TRON's λ, the active sets of the natural residual with c_k = 1/C_kk, lower where
λ_k − c_k g_k < lo_k, upper where > hi_k (g = Cλ − d), the bounds are imposed there and C_FF λ_F = d_F − C_FA λ_A
solved on the rest; repeated until the sets repeat (a semismooth Newton step each; from TRON's point this takes
one or two), at most POLISH_SWEEPS times, else RuntimeError naming the natural residual.

An edge is separated when it is unilateral, P_e = 0 and r_e − ḡ_e < −1e-9 max(|Δ|, |d|); at step 0 when
u⁰·n − ḡ < −1e-9 of max(|u⁰·n|, |ḡ|) over Γ_C; an initial state that penetrates a unilateral part by more than
1e-9 of max(|u⁰·n|, |ḡ|) at the edge is refused (the rules of the Rust solver, docs/model.md).
"""
import numpy as np

from tresca_py.dolfinx_cr.friction import TaoBoundQP, TaoStepSolver
from tresca_py.errors import InputError
from tresca_py.floating import kernel, multipliers, pin

SEPARATED = 2
POLISH_SWEEPS = 20
#: the two 1e-9 of the separation rule and the refusal of a penetrating u⁰ (module docstring)
OPEN, PENETRATION = 1e-9, 1e-9


def natural_residual(C, d, lo, hi, x):
    """max_k |x_k − P_[lo,hi](x_k − (Cx − d)_k / C_kk)|: zero exactly at the solution."""
    return float(np.max(np.abs(x - np.clip(x - (C @ x - d) / np.diag(C), lo, hi)), initial=0.0))


def polish(C, d, lo, hi, x):
    """The exact solution on the active set of ``x`` (module docstring); returns (x, sweeps)."""
    sets = None
    for sweep in range(1, POLISH_SWEEPS + 1):
        y = x - (C @ x - d) / np.diag(C)
        low, up = y < lo, y > hi
        if sets is not None and np.array_equal(low, sets[0]) and np.array_equal(up, sets[1]):
            return x, sweep - 1
        sets = (low, up)
        x = np.where(low, lo, np.where(up, hi, 0.0))
        free = ~(low | up)
        if free.any():
            rhs = d[free] - C[np.ix_(free, ~free)] @ x[~free]
            x[free] = np.linalg.solve(C[np.ix_(free, free)], rhs)
    raise RuntimeError(f"the active-set polish of TAO's solution did not settle in {POLISH_SWEEPS} sweeps "
                       f"(natural residual {natural_residual(C, d, lo, hi, x):.3e})")


def force_scale(C, d, lo, hi):
    """max_k min(max(|lo_k|, hi_k), |d_k|/C_kk): an unbounded force counts with the force that closes its gap."""
    return float(np.max(np.minimum(np.maximum(np.abs(lo), hi), np.abs(d) / np.diag(C)), initial=1e-300))


def initial_state(edges, u0, t0):
    """(gap, status) of step 0 for the CR interpolant ``u0``; InputError where u0 penetrates a unilateral part."""
    un = np.einsum("ec,ec->e", u0.reshape(-1, 2)[edges.contact], edges.normal)
    gbar = edges.gap_means(t0)
    gap = un - gbar
    over = edges.unilateral & (gap > PENETRATION * np.maximum(np.abs(un), np.abs(gbar)))
    if over.any():
        k = int(np.flatnonzero(over)[0])
        m = edges.midpoints[edges.contact[k]]
        part = edges.scene.boundaries[edges.part_of_edge[edges.contact[k]]].name
        raise InputError(f"[initial] u0: the initial state penetrates the unilateral part '{part}' at "
                         f"({m[0]:.6f}, {m[1]:.6f}): u0·n = {un[k]:e} > gap {gbar[k]:e} at t0 = {t0} (edge means)")
    scale = max(np.max(np.abs(un), initial=0.0), np.max(np.abs(gbar), initial=0.0))
    return gap, np.where(edges.unilateral & (gap < -OPEN * scale), SEPARATED, 0).astype(np.uint8)


class TaoUnilateralStepSolver(TaoStepSolver):
    """``TaoStepSolver`` with the normal unknowns: the same MUMPS factor, the step of the module docstring."""

    method = "TAO TRON on the condensed dual with normal unknowns, polished on its active set; K_r by MUMPS Cholesky"

    def _qp(self):
        e = self.disc
        self.lo = np.concatenate([-e.weight, np.where(e.unilateral, 0.0, -np.inf)])
        self.hi = np.concatenate([e.weight, np.full(len(e.weight), np.inf)])
        return TaoBoundQP(self.C, self.lo, self.hi)

    def _contact(self, d, l_full):
        """(λ, TAO iterations + polish sweeps, natural residual / force scale, the rigid motion in r: zero here)."""
        lam, its = self.qp.solve(d, self.mu)
        lam, sweeps = polish(self.C, d, self.lo, self.hi, lam)
        residual = natural_residual(self.C, d, self.lo, self.hi, lam) / force_scale(self.C, d, self.lo, self.hi)
        return lam, its + sweeps, residual, np.zeros(self.Z.shape[0])

    def step(self, l_full, u_prev_full, t=None):
        """One backward Euler step at time t; returns (u_full, info dict)."""
        e, nc = self.disc, len(self.disc.contact)
        r_free = self.solve(self.P.T @ l_full)
        s_old = np.einsum("ec,ec->e", u_prev_full.reshape(-1, 2)[e.contact], e.tangent)
        d = r_free[self.ic] - np.concatenate([s_old, e.gap_means(t)])
        lam, its, residual, rigid = self._contact(d, l_full)
        self.mu = lam.copy()
        r = r_free - self.Z @ lam + rigid
        delta = d - self.C @ lam + rigid[self.ic]
        opening = delta[nc:]
        scale = max(np.max(np.abs(delta)), np.max(np.abs(d)))
        separated = e.unilateral & (lam[nc:] <= 0) & (opening < -OPEN * scale)
        return self.P @ r, dict(iterations=its, residual=residual, mu=lam[:nc], d=d, ds=delta[:nc],
                                dof=r[self.ic[:nc]], pressure=lam[nc:] / e.lengths[e.contact], gap=opening,
                                separated=separated)


class TaoFloatingStepSolver(TaoUnilateralStepSolver):
    """A floating body (no Dirichlet part, ``tresca_py.floating``): K_# by MUMPS Cholesky, K⁺ with the pinned entries
    zeroed, and each step's equilibrium of the rigid motions by the method of multipliers around TAO and the
    polish (exact for each multiplier)."""

    method = ("TAO TRON with bounds and the method of multipliers for the rigid motions, polished on the active "
              "set; K_# by MUMPS Cholesky")

    def __init__(self, disc, K):
        if not disc.normal_unknowns:
            raise InputError("[boundary] no dirichlet part: the re-implementations take a floating body with a "
                             "unilateral part only")
        P, ic = disc.reduction()
        self.R, self.pinned = kernel(P, disc.points, disc.midpoints, ic)
        self.alpha = np.zeros(self.R.shape[1])
        self.rho_qp = None
        super().__init__(disc, K)

    def _factored(self, Kr):
        return pin(Kr, self.pinned)

    def solve(self, rhs):
        rhs = np.array(rhs, dtype=float)
        rhs[self.pinned] = 0.0
        x = super().solve(rhs)
        x[self.pinned] = 0.0
        return x

    def _contact(self, d, l_full):
        G, e = self.R[self.ic], self.R.T @ (self.P.T @ l_full)

        def inner(C, d, lam0):
            if self.rho_qp is None:                          # C + ρGGᵀ is the same at every step
                self.rho_qp = TaoBoundQP(C, self.lo, self.hi)
            lam, its = self.rho_qp.solve(d, lam0)
            lam, sweeps = polish(C, d, self.lo, self.hi, lam)
            return lam, its + sweeps

        try:
            lam, self.alpha, its, eq = multipliers(inner, self.C, d, G, e, self.mu, self.alpha)
        except RuntimeError as err:
            raise InputError(str(err)) from None
        return lam, its, eq, self.R @ self.alpha

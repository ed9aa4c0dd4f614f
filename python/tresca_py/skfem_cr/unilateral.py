"""The per-step contact problem of a scene with normal unknowns (a unilateral or a Coulomb part, issue 40): every
Γ_C edge e carries the tangential unknown s_e and the normal unknown r_e = u_n(m_e), and the contact force on the
body is −μ_e τ_e − P_e n_e (μ_e the friction force, P_e = |e| p_e the normal force). With B injecting both
(tangential ones first), C = Bᵀ K_r⁻¹ B and

    d = (s_free − s^{n−1}, r_free − ḡ),   λ = (μ, P),   Δ = d − C λ = (Δs, r − ḡ),

a step solves the dual problem min ½λᵀCλ − dᵀλ over μ_e ∈ [−w_e, w_e] (Tresca, w_e = |e| ḡa_e, on every Γ_C edge,
also where separated), P_e ∈ [0, ∞) (unilateral: P ≥ 0, r ≤ ḡ, P (r − ḡ) = 0) or (−∞, ∞) (bilateral: r = ḡ),
exactly, by the primal active-set method (``friction.bound_qp``). Coulomb replaces w_e by F̄_e |P_e|: a fixed
point over Tresca thresholds, each solved exactly, iterated until the natural residual with the thresholds of
the current P is ≤ 1e-13 of the force scale; that residual is reported.

ḡ_e is the edge mean (3-point Gauss) of the gap at tₙ. An edge is *separated* when it is unilateral, P_e = 0
and its gap is open, r_e − ḡ_e < −1e-9 · max(|Δ|, |d|) (the rule of the Rust solver; stick and slip by
``friction.classify`` with the scale max(|Δs|, |d|)). ``status`` is 0 stick, 1 slip, 2 separated; ``state`` keeps
stick/slip. Step 0 has P = 0, the gap of u⁰ and status "separated" on a unilateral edge whose gap is open by
more than 1e-9 of max(|u⁰·n|, |ḡ|) over Γ_C (the Rust solver's step-0 rule; rounding of the interpolant is not a
gap); an initial state that penetrates a unilateral part is refused, naming the part and the point.
"""
import numpy as np

from tresca_py.errors import InputError
from tresca_py.quadrature import GAUSS3_W
from tresca_py.skfem_cr.friction import StepSolver, bound_qp, classify, natural_residual

SEPARATED = 2
COULOMB_TOL, COULOMB_MAX_ITER = 1e-13, 500


class Normal:
    """Bounds, Coulomb coefficients and gaps of the normal unknowns of a ``Discretisation``."""

    def __init__(self, disc):
        self.disc = disc
        self.lo = np.where(disc.unilateral, 0.0, -np.inf)
        self.coulomb = ~np.isnan(disc.coulomb)
        self.gaps = []                                      # (gap expression, positions in disc.contact)
        for ip, b in enumerate(disc.scene.boundaries):
            if b.kind == "contact" and b.gap is not None:
                self.gaps.append((b.gap, np.flatnonzero(disc.part_of_edge[disc.contact] == ip)))

    def gap(self, t):
        """ḡ_e(t) of every Γ_C edge (zero without a gap)."""
        g = np.zeros(len(self.disc.contact))
        for expr, pos in self.gaps:
            xq, yq = self.disc.edge_points(self.disc.contact[pos])
            g[pos] = expr(xq, yq, t) @ GAUSS3_W
        return g

    def bounds(self, P):
        """(lo, hi) of λ = (μ, P) for the normal forces P: thresholds w_e or F̄_e |P_e|."""
        w = np.where(self.coulomb, np.nan_to_num(self.disc.coulomb) * np.abs(P), self.disc.weight)
        return np.concatenate([-w, self.lo]), np.concatenate([w, np.full(len(w), np.inf)])


def solve_contact(C, d, normal, lam0):
    """λ = (μ, P) of one step (module docstring); returns (λ, iterations, natural residual / force scale). Coulomb
    iterates exact Tresca solves with the thresholds F̄_e |P_e| of the previous P until the natural residual with
    the thresholds of its own P is ≤ COULOMB_TOL; InputError (naming the residual) where it does not."""
    nc = len(d) // 2
    scale = max(np.max(np.abs(d)), 1e-300)
    lam, its = lam0.copy(), 0
    for _ in range(COULOMB_MAX_ITER):
        lo, hi = normal.bounds(lam[nc:])
        lam, k = bound_qp(C, d, lo, hi, lam)
        its += k
        lo, hi = normal.bounds(lam[nc:])
        residual = natural_residual(C, d, lo, hi, lam) / max(scale, np.max(np.abs(lam)))
        if not normal.coulomb.any() or residual <= COULOMB_TOL:
            return lam, its, residual
    raise InputError(f"Coulomb friction: the fixed point over Tresca thresholds did not converge in "
                     f"{COULOMB_MAX_ITER} sweeps ({its} active-set iterations; natural residual {residual:.3e} > "
                     f"{COULOMB_TOL:g})")


PENETRATION_TOL = 1e-9


def initial_state(disc, u0, t0):
    """(gap, status) of step 0 for the CR interpolant ``u0`` (canonical vector); InputError where it penetrates a
    unilateral part by more than 1e-9 of max(|u0·n|, |ḡ|) (edge means; the Rust solver's rule)."""
    un = np.sum(u0.reshape(-1, 2)[disc.contact] * disc.normal, axis=1)
    gbar = Normal(disc).gap(t0)
    gap = un - gbar
    over = disc.unilateral & (gap > PENETRATION_TOL * np.maximum(np.abs(un), np.abs(gbar)))
    if over.any():
        k = int(np.flatnonzero(over)[0])
        e = disc.contact[k]
        part = disc.scene.boundaries[disc.part_of_edge[e]].name
        m = disc.midpoints[e]
        raise InputError(f"[initial] u0: the initial state penetrates the unilateral part '{part}' at "
                         f"({m[0]:.6f}, {m[1]:.6f}): u0·n = {un[k]:e} > gap {un[k] - gap[k]:e} at t0 = {t0} "
                         "(edge means)")
    scale = max(np.max(np.abs(un)), np.max(np.abs(gbar)))
    return gap, np.where(disc.unilateral & (gap < -PENETRATION_TOL * scale), SEPARATED, 0).astype(np.uint8)


class UnilateralStepSolver(StepSolver):
    """``StepSolver`` with the normal unknowns: the same factorisation, the step of the module docstring."""

    def __init__(self, disc, K):
        super().__init__(disc, K)
        self.normal = Normal(disc)
        self.mu = np.zeros(len(self.ic))

    def _contact(self, d, l_full):
        """(λ, iterations, residual, the rigid motion Rα in r: zero here, ``skfem_cr.floating``) of one step."""
        lam, its, residual = solve_contact(self.C, d, self.normal, self.mu)
        return lam, its, residual, np.zeros(self.Z.shape[0])

    def step(self, l_full, u_prev_full, t):
        """One backward Euler step at time t; returns (u_full, info dict)."""
        disc, nc = self.disc, len(self.disc.contact)
        r_free = self._solve(self.P.T @ l_full)
        s_old = np.sum(u_prev_full.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
        gbar = self.normal.gap(t)
        d = r_free[self.ic] - np.concatenate([s_old, gbar])
        lam, its, residual, rigid = self._contact(d, l_full)
        self.mu = lam.copy()
        r = r_free - self.Z @ lam + rigid
        delta = d - self.C @ lam + rigid[self.ic]
        state = classify(lam[:nc], delta[:nc], d, self.normal.bounds(lam[nc:])[1][:nc]).astype(np.int8)
        opening = delta[nc:]                                 # r_e - ḡ_e
        scale = max(np.max(np.abs(delta)), np.max(np.abs(d)))
        status = state.copy()
        status[(self.normal.lo == 0) & (lam[nc:] <= 0) & (opening < -1e-9 * scale)] = SEPARATED
        return self.P @ r, dict(iterations=its, residual=residual, mu=lam[:nc], d=d[:nc], ds=delta[:nc],
                                dof=r[self.ic[:nc]], pressure=lam[nc:] / disc.lengths[disc.contact], gap=opening,
                                state=state, status=status)

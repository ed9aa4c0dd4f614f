"""The dolfinx re-implementation's own step solver, with PETSc throughout (independent of the scikit-fem one's
SuperLU factorisation and primal active-set method).

With u = P r (``CrEdges.reduction``: two unknowns per free edge, one tangential unknown s_e per contact
edge) and K_r = P^T K P, backward-Euler step n is the dual problem

    min_mu  1/2 mu^T C mu - mu^T d   subject to  |mu_e| <= w_e,
    C = B^T K_r^{-1} B,   d = B^T K_r^{-1} P^T l^n - s^{n-1},

(B selects the contact unknowns, w_e = |e| gbar_e), then r = K_r^{-1} (P^T l^n - B mu). K_r is factorised once by
MUMPS Cholesky through PETSc; C comes from MUMPS solves with the contact unit vectors; the dual problem is solved
by PETSc TAO's TRON (bound-constrained trust-region Newton with the exact Hessian C, warm-started from the last
step), stopped when the projected gradient's norm is below 1e-13 of the problem's scale |d| + |C| |w|.
"""
import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede petsc4py)
import numpy as np
from petsc4py import PETSc

#: projected-gradient stopping test of TRON, relative to |d|_inf + |C|_inf |w|_inf: the exact solution is
#: a vertex/face solve of C, so TRON reaches it to rounding; 1e-13 is ~100 ulps of that scale
GATOL = 1e-13


def _seq_vec(values):
    v = PETSc.Vec().createSeq(len(values), comm=PETSc.COMM_SELF)
    v.array[:] = values
    return v


def natural_residual(C, d, w, mu):
    """|mu - P_box(mu - gamma (C mu - d))|_inf / max(w), gamma = 1/max diag C: zero exactly at the solution."""
    gamma = 1.0 / max(np.max(np.diag(C)), 1e-300)
    r = mu - np.clip(mu - gamma * (C @ mu - d), -w, w)
    return float(np.max(np.abs(r)) / max(np.max(w), 1e-300))


class TaoBoundQP:
    """min 1/2 x^T C x - x^T d subject to lo <= x <= hi (entries may be infinite) by TAO TRON (C SPD, dense, small;
    fixed per object), stopped when the projected gradient's norm is below GATOL of ``scale(d)``."""

    def __init__(self, C, lo, hi):
        n = len(lo)
        self.C, self.lo, self.hi = C, lo, hi
        self.H = PETSc.Mat().createDense((n, n), array=C.copy(), comm=PETSc.COMM_SELF)
        self.H.assemble()
        tao = PETSc.TAO().create(PETSc.COMM_SELF)
        tao.setType(PETSc.TAO.Type.TRON)
        tao.setObjectiveGradient(self._objective_gradient, _seq_vec(np.zeros(n)))
        tao.setHessian(lambda tao, x, H, P: None, self.H, self.H)      # the Hessian C is constant
        big = PETSc.INFINITY
        tao.setVariableBounds(_seq_vec(np.clip(lo, -big, big)), _seq_vec(np.clip(hi, -big, big)))
        tao.setMaximumIterations(50 * n + 100)
        tao.getKSP().setType("cg")
        tao.getKSP().getPC().setType("jacobi")
        tao.getKSP().setTolerances(rtol=1e-14)
        self.tao, self.sol, self.d = tao, _seq_vec(np.zeros(n)), np.zeros(n)

    def _objective_gradient(self, tao, x, g):
        m = x.getArray(readonly=True)
        cm = self.C @ m
        g.array[:] = cm - self.d
        return float(0.5 * m @ cm - m @ self.d)

    def scale(self, d):
        """The problem's size: |d|_inf + |C|_inf max|finite bound|."""
        finite = np.abs(np.concatenate([self.lo, self.hi]))
        finite = finite[np.isfinite(finite)]
        return np.max(np.abs(d)) + np.max(np.abs(self.C)) * (np.max(finite) if finite.size else 0.0) + 1e-300

    def solve(self, d, x0):
        """Returns (x, iterations); RuntimeError when TRON stops without convergence."""
        self.d = d
        self.tao.setTolerances(gatol=GATOL * self.scale(d), grtol=0.0, gttol=0.0)
        self.sol.array[:] = np.clip(x0, self.lo, self.hi)
        self.tao.setSolution(self.sol)
        self.tao.solve()
        reason = self.tao.getConvergedReason()
        if reason <= 0:
            raise RuntimeError(f"TAO TRON did not converge (reason {reason}) in {self.tao.getIterationNumber()} "
                               f"iterations, projected gradient {self.tao.getGradientNorm():.3e}")
        return self.sol.getArray().copy(), self.tao.getIterationNumber()


class TaoBoxQP(TaoBoundQP):
    """min 1/2 mu^T C mu - mu^T d subject to |mu| <= w by TAO TRON (C SPD, dense, small; fixed per object)."""

    def __init__(self, C, w):
        super().__init__(C, -w, w)
        self.w = w


class TaoStepSolver:
    """Factorises K_r once (MUMPS Cholesky) and solves each step's friction problem with TAO TRON."""

    method = "TAO TRON on the condensed dual (PETSc), K_r by MUMPS Cholesky"

    def __init__(self, disc, K):
        self.disc = disc
        self.P, self.ic = disc.reduction()
        Kr = (self.P.T @ K @ self.P).tocsr()
        Kr = self._factored((0.5 * (Kr + Kr.T)).tocsr()).tocsr()
        Kr.sort_indices()
        self.A = PETSc.Mat().createAIJ(size=Kr.shape, csr=(Kr.indptr.astype(PETSc.IntType),
                                                           Kr.indices.astype(PETSc.IntType), Kr.data),
                                       comm=PETSc.COMM_SELF)
        self.A.assemble()
        self.A.setOption(PETSc.Mat.Option.SPD, True)
        self.ksp = PETSc.KSP().create(PETSc.COMM_SELF)
        self.ksp.setOperators(self.A)
        self.ksp.setType("preonly")
        pc = self.ksp.getPC()
        pc.setType("cholesky")
        pc.setFactorSolverType("mumps")
        self.ksp.setUp()
        self.b, self.x = self.A.createVecs()
        self.w = disc.weight
        nc = len(self.ic)
        self.Z = np.zeros((Kr.shape[0], nc))
        e = np.zeros(Kr.shape[0])
        for k, i in enumerate(self.ic):
            e[i] = 1.0
            self.Z[:, k] = self.solve(e)
            e[i] = 0.0
        Cm = self.Z[self.ic, :]
        self.C = 0.5 * (Cm + Cm.T)
        self.mu = np.zeros(nc)
        self.qp = self._qp() if nc else None

    def _factored(self, Kr):
        """The matrix factorised for K_r (K_r itself; a floating body's K_#, ``dolfinx_cr.unilateral``)."""
        return Kr

    def _qp(self):
        """The step's bound-constrained dual problem (TAO)."""
        return TaoBoxQP(self.C, self.w)

    def solve(self, rhs):
        """K_r^{-1} rhs."""
        self.b.array[:] = rhs
        self.ksp.solve(self.b, self.x)
        if self.ksp.getConvergedReason() < 0:
            raise RuntimeError(f"MUMPS solve failed: KSP reason {self.ksp.getConvergedReason()}")
        return self.x.getArray().copy()

    def step(self, l_full, u_prev_full, t=None):
        """One backward Euler step (at time t, unused: no normal unknowns); returns (u_full, info dict)."""
        disc = self.disc
        r_free = self.solve(self.P.T @ l_full)
        if len(self.ic) == 0:
            z = np.zeros(0)
            return self.P @ r_free, dict(iterations=1, residual=0.0, mu=z, d=z, ds=z, dof=z)
        s_old = np.sum(u_prev_full.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
        d = r_free[self.ic] - s_old
        mu, its = self.qp.solve(d, self.mu)
        self.mu = mu.copy()
        r = r_free - self.Z @ mu
        return self.P @ r, dict(iterations=its, residual=natural_residual(self.C, d, self.w, mu), mu=mu, d=d,
                                ds=d - self.C @ mu, dof=r[self.ic])

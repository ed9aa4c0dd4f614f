"""An independent conforming-P2 Nitsche solver for bilateral contact with Tresca friction (scikit-fem 12).

Each backward-Euler step n solves, for u = uⁿ in P2 (nodal interpolant of u_D on Γ_D), for all v:

    a(u, v) + N(u, v) − ∫_{Γ_C} P(u) v_τ  = (lⁿ, v) + N(g_n n, v)            (Nitsche, θ = 1 normal, θ = 0 tangential)
    N(u, v) = −∫ σ_n(u) v_n − ∫ σ_n(v) u_n + ∫ p u_n v_n,     p = γ_N (λ + 2μ) / h_F  (h_F the facet length)
    P(u)    = proj_[−g_a, g_a]( σ_τ(u) − p (u_τ − u_τⁿ⁻¹) )       (Tresca on the slip increment)

with σ_n = n·σn, σ_τ = τ·σn, τ = (−n_y, n_x) written out as a constant vector of the straight contact side
(no ``w.n`` DiscreteField arithmetic, whose item assignment silently yields τ = n on scikit-fem ≥ 8), or on a
curved (polygonal) Γ_C as plain arrays of each facet's normal. A symmetry part holds its normal component at 0.
P is the consistent tangential traction: the exact solution has P(u) = σ_τ(u). The step is solved by
semismooth Newton: the generalized derivative of the projection is χ·(σ_τ(du) − p du_τ) with χ = 1 where
|σ_τ − p δu_τ| < g_a (stick), 0 where it is projected (slip). It imports nothing from tresca-cr's solvers.
"""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, FacetBasis, Functional, LinearForm, MeshTri, asm
from skfem.models.elasticity import linear_elasticity

from .problem import evaluate


class NotConverged(RuntimeError):
    """Newton did not converge in a step; the message names the step, iterations and residual."""


def _sig(G, lam, mu):
    """σ(G) = λ tr(G) I + μ (G + Gᵀ) for a gradient array G of shape (2, 2, ...)."""
    tr = G[0, 0] + G[1, 1]
    out = mu * (G + np.swapaxes(G, 0, 1))
    out[0, 0] = out[0, 0] + lam * tr
    out[1, 1] = out[1, 1] + lam * tr
    return out


def _nsn(G, lam, mu, a, b):
    """a·σ(G) b = λ tr(G) (a·b) + μ (a·G b + b·G a) for constant 2-vectors a, b."""
    ab = a[0] * b[0] + a[1] * b[1]
    aGb = sum(a[i] * G[i, j] * b[j] for i in range(2) for j in range(2))
    bGa = sum(b[i] * G[i, j] * a[j] for i in range(2) for j in range(2))
    return lam * (G[0, 0] + G[1, 1]) * ab + mu * (aGb + bGa)


def _facets(mesh, segments):
    """Facet indices of the vertex pairs ``segments`` (raises if one is not a mesh facet)."""
    look = {tuple(sorted(f)): k for k, f in enumerate(mesh.facets.T.tolist())}
    return np.array([look[tuple(sorted(s))] for s in segments], dtype=np.int64)


class Solver:
    """Set-up (mesh, bases, constant matrices) and the time loop for one problem dict (``problem.build``)."""

    CODE = "skfem-P2-nitsche"

    def __init__(self, prob):
        self.prob = prob
        self.lam, self.mu = prob["lam"], prob["mu"]
        self.lam_s = self.lam  # λ in the boundary stress σ(u)n (0 in the mixed form, where −p I replaces it)
        self.mesh = MeshTri(np.ascontiguousarray(np.asarray(prob["points"]).T),
                            np.ascontiguousarray(np.asarray(prob["triangles"]).T))
        self.basis = Basis(self.mesh, ElementVector(ElementTriP2()), intorder=6)
        pr = prob["probes"]
        self.n, self.tau = np.asarray(pr["normal"]), np.asarray(pr["tangent"])
        self.parts = {}
        for part in prob["parts"]:
            fac = _facets(self.mesh, part["segments"])
            self.parts[part["name"]] = (part, fac, FacetBasis(self.mesh, self.basis.elem, facets=fac, intorder=6))
            if part["kind"] == "contact":
                self.contact = part
                self.fb = self.parts[part["name"]][2]
        if pr.get("curved"):  # each contact facet's own outward normal (a polygonal Γ_C such as Hertz's arc)
            nrm = np.array(self.fb.normals, dtype=float)
            self.n, self.tau = nrm, np.stack([-nrm[1], nrm[0]])
        self._setup_dofs()
        self.nu = self.ndof = self.basis.N  # u unknowns; all unknowns (the mixed variant appends p)
        self.K = asm(linear_elasticity(self.lam, self.mu), self.basis)
        hf = self.mesh.facets  # facet length per contact quadrature point, shape (nel, nqp)
        fac = self.parts[self.contact["name"]][1]
        length = np.linalg.norm(self.mesh.p[:, hf[0, fac]] - self.mesh.p[:, hf[1, fac]], axis=0)
        self.pen = prob["gamma_n"] * (self.lam + 2 * self.mu) / length[:, None] * np.ones_like(self.fb.X[0][None, :])
        self.A_n = asm(BilinearForm(self._normal_form), self.fb)

    def _setup_dofs(self):
        b = self.basis
        self.comp = np.zeros(b.N, dtype=np.int64)
        for c in range(2):
            self.comp[b.nodal_dofs[c]] = c
            self.comp[b.facet_dofs[c]] = c
        dd = [b.get_dofs(facets=fac).all() for part, fac, _ in self.parts.values() if part["kind"] == "dirichlet"]
        dd += [self._symmetry_dofs(part, fac) for part, fac, _ in self.parts.values() if part["kind"] == "symmetry"]
        self.D = np.unique(np.concatenate(dd)) if dd else np.zeros(0, dtype=np.int64)

    def _symmetry_dofs(self, part, fac):
        """The dofs held at 0 by a symmetry part (u·n = 0, zero tangential traction): its normal component,
        which must be a coordinate axis (the part straight and axis-parallel) for the constraint to be a dof's."""
        pts = self.mesh.p[:, np.asarray(part["segments"]).ravel()]
        spread = np.ptp(pts, axis=1)
        if np.min(spread) > 1e-12 * np.max(spread):
            raise ValueError(f"symmetry part {part['name']!r}: this solver needs it on a line x = const or "
                             f"y = const (its points span {spread[0]:.3g} × {spread[1]:.3g})")
        c = int(np.argmin(spread))  # the normal's component
        dofs = self.basis.get_dofs(facets=fac).all()
        return dofs[self.comp[dofs] == c]

    def _normal_form(self, u, v, w):
        lam, mu, n, p = self.lam_s, self.mu, self.n, self.pen
        un, vn = u[0] * n[0] + u[1] * n[1], v[0] * n[0] + v[1] * n[1]
        return (-_nsn(u.grad, lam, mu, n, n) * vn - _nsn(v.grad, lam, mu, n, n) * un + p * un * vn)

    def interpolate(self, codes, t):
        """Nodal P2 interpolant of a 2-vector of expression codes at time t."""
        x, y = self.basis.doflocs
        out = np.zeros(self.ndof)
        for c in range(2):
            sel = np.nonzero(self.comp == c)[0]
            out[sel] = evaluate(codes[c], x[sel], y[sel], t)
        return out

    def load(self, t):
        """(lⁿ, v) + N(g_n n, v) at time t (data evaluated once at the quadrature points)."""
        lam, mu, n = self.lam_s, self.mu, self.n
        rhs = self.source(t)
        x = self.fb.global_coordinates().value
        g = evaluate(self.contact["gap"], x[0], x[1], t)

        def gap_form(v, w):
            return g * (-_nsn(v.grad, lam, mu, n, n) + self.pen * (v[0] * n[0] + v[1] * n[1]))
        return rhs + self.pad(asm(LinearForm(gap_form), self.fb)) + self.gap_load_p(g)

    def source(self, t):
        """(lⁿ, v): the body force and the Neumann tractions at time t, on all unknowns."""
        prob = self.prob
        rhs = np.zeros(self.ndof)
        if prob["f"] is not None:
            x = self.basis.global_coordinates().value
            fv = [evaluate(prob["f"][c], x[0], x[1], t) for c in range(2)]
            rhs += self.pad(asm(LinearForm(lambda v, w: fv[0] * v[0] + fv[1] * v[1]), self.basis))
        for part, _, fb in self.parts.values():
            if part["kind"] == "neumann":
                x = fb.global_coordinates().value
                tv = [evaluate(part["traction"][c], x[0], x[1], t) for c in range(2)]
                rhs += self.pad(asm(LinearForm(lambda v, w, tv=tv: tv[0] * v[0] + tv[1] * v[1]), fb))
        return rhs

    def pad(self, vec):
        """A u-space vector extended by zeros to all unknowns."""
        return np.concatenate([vec, np.zeros(self.ndof - self.nu)]) if self.ndof > self.nu else vec

    def gap_load_p(self, g):
        """The pressure rows of N(g_n n, ·) (none in the displacement formulation)."""
        return 0.0

    def traction(self, u, u_prev, t):
        """(q, P, g) at the contact quadrature points: q = σ_τ(u) − p(u_τ − u_τ_prev), P = proj(q)."""
        fu, fp = self.fb.interpolate(u[:self.nu]), self.fb.interpolate(u_prev[:self.nu])
        du = np.asarray(fu) - np.asarray(fp)
        q = _nsn(fu.grad, self.lam, self.mu, self.tau, self.n) - self.pen * (du[0] * self.tau[0] + du[1] * self.tau[1])
        x = self.fb.global_coordinates().value
        g = evaluate(self.contact["g_a"], x[0], x[1], t)
        return q, np.clip(q, -g, g), g

    def residual(self, A, rhs, u, u_prev, t):
        """R(u) and the stick indicator χ at the contact quadrature points."""
        q, P, g = self.traction(u, u_prev, t)
        tau = self.tau
        res = A @ u - rhs - self.pad(asm(LinearForm(lambda v, w: P * (v[0] * tau[0] + v[1] * tau[1])), self.fb))
        return res, (np.abs(q) < g).astype(float)

    def _factor(self):
        """Factor the constant part A = K + N on the free dofs once, and Z = A⁻¹ E_B for the contact dofs B:
        the Newton matrix is A + E_B M (M: the friction rows, nonzero on B only), solved by Woodbury."""
        if getattr(self, "_lu", None) is None:
            A = (self.K + self.A_n).tocsr()
            self.free = np.setdiff1d(np.arange(self.ndof), self.D)
            pos = -np.ones(self.ndof, dtype=np.int64)
            pos[self.free] = np.arange(self.free.size)
            cdofs = self.basis.get_dofs(facets=self.parts[self.contact["name"]][1]).all()
            self.B = pos[np.setdiff1d(cdofs, self.D)]
            self._lu = spla.splu(A[self.free][:, self.free].tocsc(), permc_spec="MMD_AT_PLUS_A")  # symmetric pattern
            E = np.zeros((self.free.size, self.B.size))
            E[self.B, np.arange(self.B.size)] = 1.0
            self._Z = self._lu.solve(E)
        return self._lu, self._Z

    def step(self, u_prev, t, tol=1e-10, max_iter=50):
        """One backward-Euler step: semismooth Newton from u_prev with the Dirichlet values at t, with a
        backtracking line search on |R| (the undamped iteration cycles when the whole of Γ_C slips: the
        all-slip Newton step overshoots and reverses every friction force)."""
        lam, mu, n, tau = self.lam, self.mu, self.n, self.tau
        rhs = self.load(t)
        u = u_prev.copy()
        if self.D.size:
            u[self.D] = self.interpolate_dirichlet(t)[self.D]
        A = self.K + self.A_n
        lu, Z = self._factor()
        free, B = self.free, self.B
        res, chi = self.residual(A, rhs, u, u_prev, t)
        scale = max(np.linalg.norm(rhs), np.linalg.norm(res[free]), 1e-300)  # |l| or the first residual
        alpha, chi_old, rnorm_old = 1.0, None, np.inf
        for it in range(1, max_iter + 1):
            rnorm = np.linalg.norm(res[free]) / scale
            if rnorm < tol:
                return u, it - 1, rnorm
            # rounding floor: a full step with an unchanged active set that no longer reduces |R| (seen at
            # λ/μ = 10⁴, where cond(A)·ε ≈ 1e-10) ends the iteration if |R| is below √tol
            if it > 1 and alpha == 1.0 and np.array_equal(chi, chi_old) and rnorm > 0.5 * rnorm_old \
                    and rnorm < np.sqrt(tol):
                return u, it - 1, rnorm
            chi_old, rnorm_old = chi, rnorm

            def jac(du, v, w, chi=chi):
                return -chi * (_nsn(du.grad, lam, mu, tau, n) - self.pen * (du[0] * tau[0] + du[1] * tau[1])) \
                    * (v[0] * tau[0] + v[1] * tau[1])
            M = self.embed(asm(BilinearForm(jac), self.fb)).tocsr()[free][:, free][B]
            y = lu.solve(-res[free])
            du = np.zeros_like(u)
            du[free] = y - Z @ np.linalg.solve(np.eye(B.size) + M @ Z, M @ y)
            u, res, chi, alpha = self.line_search(A, rhs, u, du, u_prev, t, rnorm, scale, free)
        raise NotConverged(f"skfem-nitsche: step at t={t:g} did not converge in {max_iter} Newton iterations "
                           f"(relative residual {rnorm:.3e})")

    def line_search(self, A, rhs, u, du, u_prev, t, rnorm, scale, free):
        """Backtracking on |R| over the free dofs from u along du (halving α from 1 until the residual norm
        divided by scale falls below (1 − 10⁻⁴α)·rnorm, or α < 10⁻³): (u + α du, its residual, its state, α)."""
        alpha = 1.0
        while True:
            res_new, state_new = self.residual(A, rhs, u + alpha * du, u_prev, t)
            if np.linalg.norm(res_new[free]) / scale < (1 - 1e-4 * alpha) * rnorm or alpha < 1e-3:
                return u + alpha * du, res_new, state_new, alpha
            alpha *= 0.5

    def embed(self, mat):
        """A u-space matrix as the u block of a matrix on all unknowns."""
        if self.ndof == self.nu:
            return mat
        return sp.bmat([[mat, None], [None, sp.csr_matrix((self.ndof - self.nu,) * 2)]])

    def interpolate_dirichlet(self, t):
        out = np.zeros(self.ndof)
        for part, fac, _ in self.parts.values():
            if part["kind"] == "dirichlet":
                dofs = self.basis.get_dofs(facets=fac).all()
                out[dofs] = self.interpolate(part["u"], t)[dofs]
        return out

    def run(self):
        """Backward Euler over the problem's times; returns the result dict (quantities at T)."""
        prob = self.prob
        t0 = time.perf_counter()
        times = prob["times"]
        u = self.initial(times[0])
        iters = []
        u_prev = u
        for t in times[1:]:
            u_prev = u
            u, it, _ = self.step(u_prev, t)
            iters.append(it)
        wall = time.perf_counter() - t0
        out = self.quantities(u, u_prev, times[-1])
        out.update({"code": self.CODE, "dofs": int(self.ndof), "wall_s": wall,
                    "newton_iterations": iters, "h": float(self.mesh.params().max())})
        return out

    def initial(self, t0):
        """u⁰ (nodal interpolant of the scene's u0, or 0) on all unknowns."""
        return self.interpolate(self.prob["u0"], t0) if self.prob["u0"] is not None else np.zeros(self.ndof)

    def quantities(self, u, u_prev, t):
        """The compared quantities at T (see ``quantities.summarise`` for the stick-zone and slip ones)."""
        tau = self.tau
        ub = self.basis.interpolate(u[:self.nu])
        h1 = Functional(lambda w: w.u[0] ** 2 + w.u[1] ** 2 + np.sum(w.u.grad ** 2, axis=(0, 1)))
        q, P, g = self.traction(u, u_prev, t)
        xq = self.fb.global_coordinates().value
        start = np.asarray(self.prob["probes"]["start"])
        s_q = (xq[0] - start[0]) * tau[0] + (xq[1] - start[1]) * tau[1]
        sig_int = asm(Functional(lambda w: P), self.fb)
        pr = self.prob["probes"]
        out = {"h1_norm": float(np.sqrt(asm(h1, self.basis, u=ub))), "energy": self.energy(u),
               "sigma_t_integral": float(sig_int),
               "u_tau_points": self._probe(u, pr["points"]).tolist(),
               "u_tau_samples": self._probe(u, pr["samples"]).tolist(),
               "quad_s": s_q.ravel().tolist(), "quad_stick": (np.abs(q) < g).ravel().astype(int).tolist(),
               "quad_margin": (g - np.abs(q)).ravel().tolist(), "quad_dslip": self._dslip(u, u_prev).ravel().tolist()}
        if self.prob["exact"] is not None:
            out.update(self.errors(ub, t))
        return out

    def _dslip(self, u, u_prev):
        """|δu_τ| = |(u − u_prev)·τ| at the contact quadrature points."""
        du = np.asarray(self.fb.interpolate(u[:self.nu] - u_prev[:self.nu]))
        return np.abs(du[0] * self.tau[0] + du[1] * self.tau[1])

    def energy(self, u):
        """½a(u, u) = ½∫σ(u):ε(u)."""
        lam, mu = self.lam, self.mu
        form = Functional(lambda w: 0.5 * np.sum(_sig(w.u.grad, lam, mu) * 0.5 * (w.u.grad + np.swapaxes(
            w.u.grad, 0, 1)), axis=(0, 1)))
        return float(asm(form, self.basis, u=self.basis.interpolate(u[:self.nu])))

    def _probe(self, u, pts):
        if self.prob["probes"].get("curved"):  # u·τ along the chord of a curved Γ_C means nothing
            return np.full(len(pts), np.nan)
        P = self.basis.probes(np.asarray(pts).T)
        vals = (P @ u[:self.nu]).reshape(2, -1) if P.shape[0] == 2 * len(pts) else None
        if vals is None:
            raise RuntimeError("unexpected probe matrix shape")
        return vals[0] * self.tau[0] + vals[1] * self.tau[1]

    def errors(self, ub, t):
        """True errors at t against [exact]: H1 seminorm and L2 (quadrature of degree 6)."""
        ex = self.prob["exact"]

        def semi(w):
            return sum((evaluate(ex["grad"][i][j], w.x[0], w.x[1], t) - w.u.grad[i, j]) ** 2
                       for i in range(2) for j in range(2))

        def l2(w):
            return sum((evaluate(ex["u"][i], w.x[0], w.x[1], t) - w.u[i]) ** 2 for i in range(2))
        return {"err_h1_semi": float(np.sqrt(asm(Functional(semi), self.basis, u=ub))),
                "err_l2": float(np.sqrt(asm(Functional(l2), self.basis, u=ub)))}


def solve(prob, solver_class=Solver):
    """Run one problem dict with ``solver_class`` (this displacement solver or the mixed one in
    ``skfem_mixed``); returns the result dict."""
    t0 = time.perf_counter()
    solver = solver_class(prob)
    setup = time.perf_counter() - t0
    out = solver.run()
    out["wall_s"] += setup  # set-up + time loop; the post-processing of the quantities is not counted
    return out

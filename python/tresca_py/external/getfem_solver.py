#!/usr/bin/python3
"""GetFEM 5.4 (Debian python3-getfem) solver for bilateral contact with Tresca friction, P1 or P2 Lagrange,
and for unilateral contact with Tresca or Coulomb friction (``Solver._unilateral_terms``).

Standalone: it imports only numpy, getfem and the standard library, because Debian's GetFEM lives under
/usr/bin/python3 (3.11), outside the project's venv. Usage:

    /usr/bin/python3 getfem_solver.py problem.json result.json

``problem.json`` is ``tresca_py.external.problem.build(...)`` (expressions as numpy code in x, y, t).
GetFEM's machinery does the work:

* ``add_isotropic_linearized_elasticity_brick`` (a(u, v)), ``add_source_term_brick`` (f and tractions),
  ``add_Dirichlet_condition_with_multipliers`` (u = u_D weakly on the trace space of mfu; the variant "with
  simplification" clears matrix rows at every assembly and made the assembly grow ~30× per refinement);
* ``add_normal_Dirichlet_condition_with_multipliers`` for a symmetry part (u·n = 0, no tangential traction);
* ``add_normal_Dirichlet_condition_with_Nitsche_method`` (θ = 1) for the bilateral condition u·n = g_n with
  Neumann term ``Model.Neumann_term`` (σ(u)n) and γ = γ₀ h_T, γ₀ = 1/(γ_N (λ + 2μ));
* Tresca friction on the slip increment as a Nitsche term in GWFL with GetFEM's ``Ball_projection``
  (θ = 0):  −∫_{Γ_C} P·v,  P = Ball_projection((I − n⊗n)(σ(u)n − (u − uⁿ⁻¹)/γ), g_a),  γ = γ₀ element_size;
* the model's own Newton (``Model.solve``, line search "basic": the "default" one stalls on Example 5.1
  at refine 4 with P2 — residual stuck at half its initial value for 100 iterations) per backward-Euler step.
"""
import json
import sys
import time

import numpy as np
import getfem as gf

gf.util_trace_level(0)
gf.util_warning_level(0)

SIGMA = "(lambda*Trace(Grad_u)*Id(2) + mu*(Grad_u + Grad_u'))"
# mixed (Taylor–Hood P2/P1, p = −λ div u): σ(u, p) = 2μ ε(u) − p I; bulk 2μ(ε(u), ε(v)) − (p, div v) − (q, div u)
# − (p, q)/λ; symmetric normal Nitsche term with σ(u, p) (θ = 1, as the brick in the displacement form)
SIGMA_M = "(2*mu*Sym(Grad_u) - p*Id(2))"
BULK_M = "2*mu*Sym(Grad_u):Grad_Test_u - p*Div_Test_u - Test_p*Div_u - p*Test_p/lambda"
NITSCHE_M = ("-(" + SIGMA_M + "*Normal).Normal*(Test_u.Normal)"
             " - ((2*mu*Sym(Grad_Test_u) - Test_p*Id(2))*Normal).Normal*(u.Normal - GAP)"
             " + (u.Normal - GAP)*(Test_u.Normal)/(gamma0*element_size)")
PROJ = ("Ball_projection((Id(2) - Normal@Normal)*(" + SIGMA + "*Normal - (u - UP)/(gamma0*element_size)), GA)")
QTAU = "Norm((Id(2) - Normal@Normal)*(" + SIGMA + "*Normal - (u - UP)/(gamma0*element_size)))"
FLOOR = 1e-8  # accepted relative residual of a stalled Newton iteration (rounding; see Solver.run)
CONTACT = 10  # region numbers: CONTACT for Γ_C, 11, 12, ... for the other parts


def evaluate(src, x, y, t):
    """A numpy code string of (x, y, t) at points (the problem format; see problem.evaluate)."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    with np.errstate(all="ignore"):
        val = eval(src, {"numpy": np, "x": x, "y": y, "t": float(t), "__builtins__": {}})  # noqa: S307
    return np.broadcast_to(np.asarray(val, dtype=float), x.shape).copy()


def region_faces(m, outer, pts):
    """Outer faces of mesh m whose vertices all lie in the vertex set ``pts`` (coordinates)."""
    pids = m.pid_from_coords(np.asarray(pts).T, 1e-10)
    faces = m.faces_from_pid(np.asarray(pids, dtype=np.int32))
    keep = {(int(c), int(f)) for c, f in outer.T}
    sel = [k for k in range(faces.shape[1]) if (int(faces[0, k]), int(faces[1, k])) in keep]
    return faces[:, sel]


class Solver:
    def __init__(self, prob):
        self.prob = prob
        k = int(prob["degree"])
        P, T = np.asarray(prob["points"]).T, np.asarray(prob["triangles"]).T
        self.m = gf.Mesh("pt2D", P, T)
        outer = self.m.outer_faces()
        self.mfu = gf.MeshFem(self.m, 2)
        self.mfu.set_classical_fem(k)
        self.mfd = gf.MeshFem(self.m, 1)
        self.mfd.set_classical_fem(k + 1)
        self.mim = gf.MeshIm(self.m, gf.Integ("IM_TRIANGLE(6)"))
        md = self.md = gf.Model("real")
        md.add_fem_variable("u", self.mfu)
        md.add_initialized_data("lambda", prob["lam"])
        md.add_initialized_data("mu", prob["mu"])
        md.add_initialized_data("gamma0", 1.0 / (prob["gamma_n"] * (prob["lam"] + 2 * prob["mu"])))
        self.mixed = bool(prob.get("mixed"))
        if self.mixed:
            self.mfp = gf.MeshFem(self.m, 1)
            self.mfp.set_classical_fem(k - 1)  # continuous P1 pressure with P2 displacement: Taylor–Hood
            md.add_fem_variable("p", self.mfp)
            md.add_linear_term(self.mim, BULK_M)
        else:
            md.add_isotropic_linearized_elasticity_brick(self.mim, "u", "lambda", "mu")
        self.xd = self.mfd.basic_dof_nodes()
        self.xu = self.mfu.basic_dof_nodes()
        self.data = []  # (name, mf, codes-or-code, component or None)
        if prob["f"] is not None:
            self._fem_data("F", prob["f"])
            md.add_source_term_brick(self.mim, "u", "[F1;F2]")
        pts = np.asarray(prob["points"])
        for i, part in enumerate(prob["parts"]):
            verts = pts[np.unique(np.asarray(part["segments"]).ravel())]
            rg = CONTACT if part["kind"] == "contact" else 11 + i
            self.m.set_region(rg, region_faces(self.m, outer, verts))
            if part["kind"] == "neumann":
                self._fem_data(f"T{i}_", part["traction"])
                md.add_source_term_brick(self.mim, "u", f"[T{i}_1;T{i}_2]", rg)
            elif part["kind"] == "dirichlet":
                md.add_initialized_fem_data(f"UD{i}", self.mfu, np.zeros(self.mfu.nbdof()))
                self.data.append((f"UD{i}", "u", part["u"], None))
                md.add_Dirichlet_condition_with_multipliers(self.mim, "u", self.mfu, rg, f"UD{i}")
            elif part["kind"] == "symmetry":  # u·n = 0 (multiplier of degree k), zero tangential traction
                md.add_normal_Dirichlet_condition_with_multipliers(self.mim, "u", k, rg)
            else:
                self.contact = part
        self._scalar_data("GAP", self.contact["gap"])
        self._scalar_data("GA", self.contact["g_a"])
        md.add_initialized_fem_data("UP", self.mfu, np.zeros(self.mfu.nbdof()))
        self.unilateral = self.contact.get("law") == "unilateral"
        if self.unilateral:
            self._unilateral_terms()
        elif self.mixed:
            md.add_nonlinear_term(self.mim, NITSCHE_M, CONTACT)
            md.add_nonlinear_term(self.mim, "-" + PROJ.replace(SIGMA, SIGMA_M) + ".Test_u", CONTACT)
        else:
            md.add_normal_Dirichlet_condition_with_Nitsche_method(self.mim, "u", md.Neumann_term("u", CONTACT),
                                                                  "gamma0", CONTACT, 1.0, "GAP")
            md.add_nonlinear_term(self.mim, "-" + PROJ + ".Test_u", CONTACT)

    def _unilateral_terms(self):
        """Signorini with Tresca or Coulomb friction (Chouly–Hild–Renard Nitsche, θ = 0): −∫_{Γ_C} P·v with P
        GetFEM's ``Coulomb_friction_coupled_projection`` of the reaction r(u) = σ(u)n − t_C at the gap
        g − u·n, the slip increment u − uⁿ⁻¹ and r = 1/(γ₀ h): normal part −(r_n(u) − (u·n − g)/(γ₀h))₋,
        tangential part its ball projection of radius f; f = [0, g_a, g_a] is Tresca's threshold g_a (adhesion
        τ_adh = g_a capped at g_a, also on separated points), a scalar f = F is Coulomb's F·pressure."""
        md, c = self.md, self.contact
        lam_expr = SIGMA + "*Normal"
        if c.get("contact_traction") is not None:
            self._fem_data("TC", c["contact_traction"])
            md.add_source_term_brick(self.mim, "u", "[TC1;TC2]", CONTACT)
            lam_expr = "(" + lam_expr + " - [TC1;TC2])"
        if c.get("coulomb") is not None:
            self._scalar_data("FC", c["coulomb"])
            fr = "FC"
        else:
            fr = "[0;GA;GA]"
        self.lam_expr = lam_expr
        self.cfp = (f"Coulomb_friction_coupled_projection({lam_expr}, Normal, u-UP, GAP-u.Normal, {fr}, "
                    "1/(gamma0*element_size))")
        md.add_nonlinear_term(self.mim, "-" + self.cfp + ".Test_u", CONTACT)

    def _scalar_data(self, name, src):
        self.md.add_initialized_fem_data(name, self.mfd, np.zeros(self.mfd.nbdof()))
        self.data.append((name, "d", src, None))

    def _fem_data(self, prefix, codes):
        for c in range(2):
            self._scalar_data(f"{prefix}{c + 1}", codes[c])

    def vector_values(self, codes, t):
        """Nodal interpolant on mfu (dofs interleaved x, y per node) of a 2-vector of codes."""
        out = np.zeros(self.mfu.nbdof())
        for c in range(2):
            out[c::2] = evaluate(codes[c], self.xu[0, c::2], self.xu[1, c::2], t)
        return out

    def set_time(self, t):
        for name, where, src, _ in self.data:
            if where == "u":
                self.md.set_variable(name, self.vector_values(src, t))
            else:
                self.md.set_variable(name, evaluate(src, self.xd[0], self.xd[1], t))

    def run(self, tol=1e-10, max_iter=40):
        prob, md = self.prob, self.md
        t0 = time.perf_counter()
        times = prob["times"]
        u = self.vector_values(prob["u0"], times[0]) if prob["u0"] is not None else np.zeros(self.mfu.nbdof())
        md.set_variable("u", u)
        iters = []
        for n, t in enumerate(times[1:], start=1):
            md.set_variable("UP", md.variable("u"))
            self.set_time(t)
            md.assembly("build_rhs")
            r0 = max(float(np.linalg.norm(md.rhs())), 1e-300)
            target = tol * r0  # relative to the step's first residual
            nit = self.newton(n, t, target, r0, max_iter)
            iters.append(int(nit))
        wall = time.perf_counter() - t0
        out = self.quantities(times[-1])
        dofs = self.mfu.nbdof() + (self.mfp.nbdof() if self.mixed else 0)
        out.update({"code": "getfem-TH" if self.mixed else f"getfem-P{prob['degree']}", "dofs": int(dofs),
                    "wall_s": wall,
                    "newton_iterations": iters})
        return out

    def newton(self, n, t, target, r0, max_iter):
        """GetFEM's Newton for step n from the previous u; the iteration count. Unilateral: from the same start
        with the line searches "basic", then "simplest", then "systematic" until one converges (the semismooth
        iteration cycles with "basic" on sig_moving, P1, 64×64 cells, step 5, residual 2.9e-3·r0 after 40
        iterations, and with "simplest" on sig_moving, P2, 4×4 cells, step 7); bilateral: "basic" only."""
        md, start, msg = self.md, self.md.variable("u"), ""
        if self.unilateral:  # the Coulomb coupled projection took 82 iterations (sig_coulomb, P2, 32×32 cells)
            max_iter = max(max_iter, 150)
        for search in ("basic", "simplest", "systematic") if self.unilateral else ("basic",):
            md.set_variable("u", start)
            nit, converged = md.solve("max_res", target, "max_iter", max_iter, "lsearch", search)
            md.assembly("build_rhs")
            rnorm = float(np.linalg.norm(md.rhs()))
            # rounding floor: at λ/μ = 10⁴ (cep, P1, 64×64 cells) Newton stalls at ~1e-9·r0 ≈ ε·cond(A); a
            # stalled iteration below FLOOR·r0 is accepted, anything else is a failure
            if np.isfinite(rnorm) and rnorm <= (10 * target if converged else FLOOR * r0):
                return int(nit)
            msg += f"; {search}: {nit} Newton iterations, residual {rnorm:.3e}"
        raise RuntimeError(f"getfem: step {n} (t={t:g}) did not converge (target {target:.3e}){msg}")

    def quantities(self, t):
        md, mim, mfu, pr = self.md, self.mim, self.mfu, self.prob["probes"]
        U = md.variable("u")
        tau = np.asarray(pr["tangent"])
        l2, semi = gf.compute_L2_norm(mfu, U, mim), gf.compute_H1_semi_norm(mfu, U, mim)
        # the mixed form's own energy ½(2μ‖ε(u)‖² + ‖p‖²/λ), = ½a(u, u) when p = −λ div u
        energy = gf.asm("generic", mim, 0, "mu*Sym(Grad_u):Sym(Grad_u) + 0.5*p*p/lambda" if self.mixed
                        else "0.5*(" + SIGMA + "):Sym(Grad_u)", -1, md)
        sig_expr = SIGMA_M if self.mixed else SIGMA
        mimd2, mimd1 = gf.MeshImData(mim, CONTACT, [2]), gf.MeshImData(mim, CONTACT)
        extra = {}
        if self.unilateral:
            sig = gf.asm("generic", mim, 0, "[-Normal(2);Normal(1)]." + self.cfp, CONTACT, md)
            extra = {"normal_force": float(gf.asm("generic", mim, 0, "-Normal." + self.cfp, CONTACT, md)),
                     "pressure_x2": float(gf.asm("generic", mim, 0, "-Normal." + self.cfp + "*X(1)*X(1)",
                                                 CONTACT, md)),
                     "max_pressure": float(np.max(md.interpolation("-Normal." + self.cfp, mimd1, CONTACT)))}
            margin = np.zeros(0)
        else:
            sig = gf.asm("generic", mim, 0, "[-Normal(2);Normal(1)]." + PROJ.replace(SIGMA, sig_expr), CONTACT, md)
            margin = np.asarray(md.interpolation("GA - " + QTAU.replace(SIGMA, sig_expr), mimd1, CONTACT))
        xq = np.asarray(md.interpolation("X", mimd2, CONTACT)).reshape(-1, 2).T
        stick = margin > 0
        dslip = np.asarray(md.interpolation("Norm((Id(2) - Normal@Normal)*(u - UP))", mimd1, CONTACT))
        start = np.asarray(pr["start"])
        s_q = (xq[0] - start[0]) * tau[0] + (xq[1] - start[1]) * tau[1]

        def probe(points):
            if pr.get("curved"):  # u·τ along the chord of a curved Γ_C means nothing (problem.contact_probes)
                return np.full(len(points), np.nan)
            v = np.asarray(md.interpolation("u", np.asarray(points).T, self.m)).reshape(-1, 2).T
            return v[0] * tau[0] + v[1] * tau[1]
        out = {"h1_norm": float(np.hypot(l2, semi)), "energy": float(energy), "sigma_t_integral": float(sig),
               "u_tau_points": probe(pr["points"]).tolist(), "u_tau_samples": probe(pr["samples"]).tolist(),
               "quad_s": s_q.tolist(), "quad_stick": stick.astype(int).tolist(), "quad_margin": margin.tolist(),
               "quad_dslip": dslip.tolist(), **extra}
        if self.prob["exact"] is not None:
            out.update(self.errors(U, t))
        return out

    def errors(self, U, t):
        """True errors at t: u_h and the exact u on P_{k+2} (the exact u enters by its nodal interpolant of
        degree k+2, whose error is O(h^{k+1}) in H1 for smooth u, one order above the P_k error)."""
        k = int(self.prob["degree"])
        mfh = gf.MeshFem(self.m, 2)
        mfh.set_classical_fem(k + 2)
        xh = mfh.basic_dof_nodes()
        ex = np.zeros(mfh.nbdof())
        for c in range(2):
            ex[c::2] = evaluate(self.prob["exact"]["u"][c], xh[0, c::2], xh[1, c::2], t)
        diff = ex - gf.compute_interpolate_on(self.mfu, U, mfh)
        return {"err_h1_semi": float(gf.compute_H1_semi_norm(mfh, diff, self.mim)),
                "err_l2": float(gf.compute_L2_norm(mfh, diff, self.mim))}


def main(argv):
    if len(argv) != 3:
        print("usage: getfem_solver.py problem.json result.json", file=sys.stderr)
        return 2
    try:
        with open(argv[1]) as fh:
            prob = json.load(fh)
    except (OSError, ValueError) as err:
        print(f"error: cannot read the problem file {argv[1]}: {err}", file=sys.stderr)
        return 2
    try:
        t0 = time.perf_counter()
        solver = Solver(prob)
        setup = time.perf_counter() - t0
        out = solver.run()
        out["wall_s"] += setup  # set-up + time loop (not the interpreter start, not the post-processing)
    except RuntimeError as err:
        print(f"error: {err}", file=sys.stderr)
        return 1
    with open(argv[2], "w") as fh:
        json.dump(out, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

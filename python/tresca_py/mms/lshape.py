"""mms_lshape (issue 33, A4): a manufactured Tresca problem on the L-shape (0,2)² ∖ [1,2]² whose exact
solution carries the re-entrant corner's singularity, so adaptive and uniform refinement are compared on
true errors.

    u = u_T + c (1+t) χ(r) w,

* w: the Williams mode of the corner (1, 1) (:mod:`tresca_py.mms.williams`), ∇w ~ r^(λ−1), λ = 0.5444837;
* χ(r) = S((3/4 − r)/(1/2)), S the quintic smoothstep of :mod:`tresca_py.mms.blocks`: 1 for r < 1/4, 0 for
  r > 3/4, so χw vanishes on every side at distance 1 from the corner (floor, clamp, right, top) and the
  body force f = −div σ(χw) = −σ(w)∇χ − div(λ_L (w·∇χ) I + μ (w⊗∇χ + ∇χ⊗w)) (div σ(w) = 0) is smooth;
* u_T: mms_stick_to_slip's construction (:mod:`tresca_py.mms.cases`) on the floor y = 0 stretched to
  x ∈ (0, 2) (X = x/2 in its front): slip zone 0 < x < 2ξ(t), ξ = 1/5 + 3t/5, points pass stick → slip only,
  so backward Euler is exact at the time nodes (no time error);
* c = 1/25: the singular part's energy ½∫σ:ε at t = T then equals u_T's to within 5 % (:func:`energies`;
  with c = 1/100 it was 0.06 of it, and energy scales with c²: c = (0.536/318)^(1/2) = 0.041, rounded to 1/25).
  Chosen from the energies alone, before any solver run; the derivation prints the ratio.

Sides (verification/cases/lshape_sides.msh): floor (contact), clamp x = 0 (Dirichlet, u_D = u_T there),
Neumann right, ledge, notch, top with σ(u)n (on right and top σ(u_T)n, χw being zero there).
"""
import numpy as np
import sympy as sp

from tresca_py.expr import ExprError, lint, symbols
from tresca_py.mms import williams
from tresca_py.mms.blocks import PosPow, SStep, lam
from tresca_py.mms.checks import check_contact, check_fields, check_roundtrip
from tresca_py.mms.tresca_law import np_grad, stress_np
from tresca_py.mms.derive import CheckFailed, require
from tresca_py.elastic import lame
from tresca_py.mms.elasticity import Xs, body_force, grad_of, local_field, stress, to_global
from tresca_py.mms.exmex import ex

x, y, t = symbols()
R = sp.Rational
SEGMENTS = {"floor": ((0, 0), (2, 0)), "right": ((2, 0), (2, 1)), "ledge": ((2, 1), (1, 1)),
            "notch": ((1, 1), (1, 2)), "top": ((1, 2), (0, 2)), "clamp": ((0, 2), (0, 0))}
KINDS = {"floor": "contact", "right": "neumann", "ledge": "neumann", "notch": "neumann", "top": "neumann",
         "clamp": "dirichlet"}
NEAR = ("ledge", "notch")          # the sides χw reaches
C_SING = R(1, 25)
R_CORNER = sp.sqrt((x - 1) ** 2 + (y - 1) ** 2)


def normal(side):
    """Outward unit normal of a side (the polygon runs counter-clockwise)."""
    (ax, ay), (bx, by) = SEGMENTS[side]
    d = sp.Matrix([bx - ax, by - ay])
    d = d / sp.sqrt(d.dot(d))
    return sp.Matrix([d[1], -d[0]])


def region(rng, n, r_min=0.01):
    """n random points of the L-shape at distance ≥ r_min from the corner (finite differences need it)."""
    out = np.empty((0, 2))
    while len(out) < n:
        p = rng.random((2 * n, 2)) * 2
        keep = ~((p[:, 0] > 1) & (p[:, 1] > 1)) & (np.hypot(p[:, 0] - 1, p[:, 1] - 1) >= r_min)
        out = np.vstack([out, p[keep]])
    return out[:n, 0], out[:n, 1]


def parts(E, nu):
    """(u_T, χ, w) of the case."""
    lam_, mu = lame(E, nu)
    g0, A = R(1, 5), R(1, 10)
    xi = R(1, 5) + R(3, 5) * t
    ga = g0 * (1 + Xs / 4)
    s = A * PosPow(xi - Xs / 2, 3)
    lam_t = -ga + g0 * PosPow(Xs / 2 - xi, 3)
    U1, U2 = local_field(s, lam_t, mu, (1 + t) * sp.cos(Xs / 2) / 20, (1 + Xs / 2) * (1 + t / 2) / 20)
    u_T, _ = to_global(U1, U2, 1, 0)
    chi = SStep((R(3, 4) - R_CORNER) / R(1, 2), 0)
    return u_T, chi, williams.field(nu), ga.subs(Xs, x)


def case_lshape():
    E, nu = R(10), R(3, 10)
    u_T, chi, w, ga = parts(E, nu)
    u = [u_T[i] + C_SING * (1 + t) * chi * w[i] for i in range(2)]
    return dict(name="mms_lshape", title="MMS: L-shape with the re-entrant corner's singularity, Tresca floor",
                E=E, nu=nu, u=u, u_T=u_T, chi=chi, w=w, g_a=ga, T=1, steps=4, region=region,
                expect={"stick_to_slip": True, "slip_to_stick": False})


def singular_force(w, chi, lam_, mu):
    """−div σ(χw) for div σ(w) = 0: −σ(w)∇χ − div(λ_L (w·∇χ) I + μ (w⊗∇χ + ∇χ⊗w))."""
    gchi = sp.Matrix([sp.diff(chi, x), sp.diff(chi, y)])
    wv = sp.Matrix(w)
    A = lam_ * wv.dot(gchi) * sp.eye(2) + mu * (wv * gchi.T + gchi * wv.T)
    Sw = stress(grad_of(w), lam_, mu) * gchi
    fa = body_force(A)
    return [fa[0] - Sw[0], fa[1] - Sw[1]]


def printed(e, vals):
    """exmex text of ``e`` with λ and Q written as their doubles."""
    s = ex(e)
    for sym, v in vals.items():
        s = s.replace(sym.name, repr(float(v)))
    return s


def derive(case):
    """All data of the case (as tresca_py.mms.derive.derive, with the L-shape's sides)."""
    lam_, mu = lame(case["E"], case["nu"])
    u, u_T = case["u"], case["u_T"]
    G, G_T = grad_of(u), grad_of(u_T)
    S, S_T = stress(G, lam_, mu), stress(G_T, lam_, mu)
    f_T, f_W = body_force(S_T), singular_force(case["w"], case["chi"], lam_, mu)
    f = [f_T[i] + C_SING * (1 + t) * f_W[i] for i in range(2)]
    sym = {"u1": u[0], "u2": u[1], "f1": f[0], "f2": f[1], "u0_1": u[0].subs(t, 0), "u0_2": u[1].subs(t, 0),
           "grad11": G[0, 0], "grad12": G[0, 1], "grad21": G[1, 0], "grad22": G[1, 1], "g_a": case["g_a"]}
    for side, kind in KINDS.items():
        if kind == "neumann":
            g = (S if side in NEAR else S_T) * normal(side)
            sym[f"g_{side}_1"], sym[f"g_{side}_2"] = g[0], g[1]
        if kind == "dirichlet":
            sym[f"uD_{side}_1"], sym[f"uD_{side}_2"] = u_T[0].subs(x, 0), u_T[1].subs(x, 0)
    vals = williams.values()
    d = dict(case, lam=lam_, mu=mu, vals=vals, sym={k: v.xreplace(vals) for k, v in sym.items()})
    d["str"] = {k: printed(v, vals) for k, v in sym.items()}
    for k, v in d["str"].items():
        try:
            lint(v)
        except ExprError as err:
            raise CheckFailed(f"mms_lshape: {k} violates exmex syntax rules: {err}") from None
    return d


def side_points(side, n=201, nt=21, T=1.0):
    """(X, Y, T) grids along a side (its end points left out: the corner's gradient is infinite)."""
    (ax, ay), (bx, by) = SEGMENTS[side]
    s = np.linspace(0, 1, n)[1:-1]
    S_, TT = np.meshgrid(s, np.linspace(0, T, nt), indexing="ij")
    return ax + S_ * (bx - ax), ay + S_ * (by - ay), TT


def check_sides(d, log):
    """Printed traction = σ(printed grad) n on every Neumann side, u_D = u on the clamp (parsed strings)."""
    P = d["parsed"]
    Gf = np_grad(d)
    for side, kind in KINDS.items():
        X, Y, T = side_points(side, T=float(d["T"]))
        if kind == "neumann":
            n = [float(v) for v in normal(side)]
            s11, s12, s22 = stress_np(Gf, float(d["lam"]), float(d["mu"]), X, Y, T)
            g1, g2 = lam(P[f"g_{side}_1"])(X, Y, T), lam(P[f"g_{side}_2"])(X, Y, T)
            err = max(np.max(np.abs(s11 * n[0] + s12 * n[1] - g1)), np.max(np.abs(s12 * n[0] + s22 * n[1] - g2)))
            scale = max(1.0, np.max(np.abs(s11)), np.max(np.abs(s12)), np.max(np.abs(s22)))
            require(err < 1e-12 * scale, f"mms_lshape: traction on {side} != sigma n ({err:.2e})")
        if kind == "dirichlet":
            err = max(np.max(np.abs(lam(P[f"uD_{side}_{i}"])(X, Y, T) - lam(P[f"u{i}"])(X, Y, T)))
                      for i in (1, 2))
            require(err < 1e-14, f"mms_lshape: u_D != u on {side} ({err:.2e})")
    log("g = sigma(u) n on right, ledge, notch, top; u_D = u on the clamp (200 x 21 samples each)   ok")


def energies(d, t_eval=1.0, n=120):
    """(energy of u_T, energy of χw scaled by c(1+t)) at t = t_eval: ½∫σ(v):ε(v), by Gauss–Legendre on the
    three unit squares for u_T and on the wedge in (s, θ), r = (3/4)s², for the singular part."""
    lam_, mu = float(d["lam"]), float(d["mu"])
    g, wq = np.polynomial.legendre.leggauss(n)
    g, wq = (g + 1) / 2, wq / 2

    def density(G, X, Y):
        s11, s12, s22 = stress_np(G, lam_, mu, X, Y, np.full_like(X, t_eval))
        e = [[G[i][j](X, Y, np.full_like(X, t_eval)) for j in range(2)] for i in range(2)]
        return 0.5 * (s11 * e[0][0] + s22 * e[1][1] + s12 * (e[0][1] + e[1][0]))

    def grads(v):
        Gv = grad_of(v)
        return [[lam(Gv[i, j].xreplace(d["vals"])) for j in range(2)] for i in range(2)]

    e_T = 0.0
    for ox, oy in ((0, 0), (1, 0), (0, 1)):
        X, Y = np.meshgrid(ox + g, oy + g, indexing="ij")
        e_T += np.sum(np.outer(wq, wq) * density(grads(d["u_T"]), X, Y))
    s, th = np.meshgrid(g, -3 * np.pi / 4 + 1.5 * np.pi * g, indexing="ij")
    r = 0.75 * s ** 2
    phi = 5 * np.pi / 4 + th                     # the body's bisector points along 5π/4
    X, Y = 1 + r * np.cos(phi), 1 + r * np.sin(phi)
    sing = [C_SING * (1 + t) * d["chi"] * wi for wi in d["w"]]
    jac = r * 1.5 * s * 1.5 * np.pi                # r dr dθ, dr = 1.5 s ds, dθ = 1.5π dg
    e_W = np.sum(np.outer(wq, wq) * density(grads(sing), X, Y) * jac)
    return e_T, e_W


def run_checks(case, log=print):
    """Derive and check mms_lshape: the Williams mode (symbolic), read-back, derivatives, sides, Tresca."""
    div, faces = williams.polar_checks(case["nu"])
    require(div == [0, 0], f"mms_lshape: div sigma(w) = {div}, not 0")
    root = williams.exponent()
    q = williams.q_of(root).evalf(30)
    worst = max(abs(sp.N(f.subs({williams.LAM: root, williams.Q: q, sp.Symbol("r", positive=True): rr}), 30))
                for f in faces for rr in (R(1, 10), R(1, 2)))
    # the root has 30 digits: the face tractions, O(1) terms, cancel to about 1e-30
    require(worst < 1e-25, f"mms_lshape: Williams faces not traction-free ({worst:.1e})")
    log(f"Williams mode: div sigma = 0 (symbolic), faces free to {float(worst):.1e} at lambda = {float(root):.10f}")
    rng = np.random.default_rng(20240611)
    d = derive(case)
    check_roundtrip(d, rng, log)
    check_fields(d, rng)
    log("grad = FD(u), f = -div sigma (FD and symbolic), u0 = u(., 0) at 400 points (r >= 0.01)   ok")
    check_sides(d, log)
    floor = dict(d, name="mms_lshape", corners=[[0, 0], [2, 0], [2, 1], [0, 1]], kinds={"bottom": "contact"})
    check_contact(floor, log)
    d["energies"] = energies(d)
    log("energy at t = T: u_T %.4e, c(1+t) chi w %.4e (ratio %.2f)" % (*d["energies"],
                                                                       d["energies"][1] / d["energies"][0]))
    return d


HEADER = """\
L-shape (0,2)^2 minus [1,2]^2 with the re-entrant corner's singularity and Tresca friction on its floor
(issue 33, requirement A4 of the adaptive study): true errors for adaptive against uniform refinement.
  u = u_T + c (1+t) chi(r) w,   c = 1/25,   r = |(x,y) - (1,1)|
  w     Williams symmetric mode of the traction-free corner (1,1) (interior angle 3pi/2), plane strain:
        in the wedge frame (xi along the bisector towards (0,0), theta = atan2(x-y, 2-x-y) from it)
        u_xi = r^lam [(k - Q(lam+1)) cos(lam th) - lam cos((lam-2) th)],
        u_eta = r^lam [(k + Q(lam+1)) sin(lam th) + lam sin((lam-2) th)],  k = 3 - 4 nu,
        lam = 0.544483736782464 (lam sin(3pi/2) + sin(3 lam pi/2) = 0), Q = -cos((lam-1)3pi/4)/cos((lam+1)3pi/4),
        w = (u_eta - u_xi, -u_xi - u_eta); grad w ~ r^(lam-1): uniform refinement converges like h^lam.
  chi   S((3/4 - r)/(1/2)), S the quintic smoothstep: 1 for r < 1/4, 0 for r > 3/4 (w never reaches y = 0).
  u_T   mms_stick_to_slip stretched to 0 < x < 2: slip s = (1/10) max(0, xi - x/2)^3, xi = 1/5 + 3t/5,
        sigma_t.tau = -g_a + (1/5) max(0, x/2 - xi)^3, g_a = (1/5)(1 + x/4); points pass stick -> slip only
        (backward Euler exact at the nodes); u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x/2)/20,
        u2 = y(1-y)(1+x/2)(1+t/2)/20.
  c makes the singular part's energy at t = T equal u_T's to within 5 % (%ENERGY%).
Sides (lshape_sides.msh): floor y = 0 contact; clamp x = 0 Dirichlet u = u_T; right, ledge, notch, top Neumann
sigma(u) n. E = 10, nu = 0.3. Derivation and checks: python/tresca_py/mms/lshape.py, williams.py.
Measured: reference/adaptive.md."""


def scene_text(d):
    """The scene TOML of mms_lshape."""
    st = d["str"]
    e_T, e_W = d["energies"]
    header = HEADER.replace("%ENERGY%", f"energies {e_T:.4f} and {e_W:.4f}")
    L = ["# Manufactured solution -- GENERATED by verification/mms/derive.py, do not edit by hand."]
    L += ["# " + line for line in header.split("\n")]
    L += ["#", "# Regenerate: .venv/bin/python verification/mms/derive.py", "",
          f'title = "{d["title"]}"', "", "[mesh]", 'file = "lshape_sides.msh"', "", "[material]",
          f"E  = {float(d['E'])!r}", f"nu = {float(d['nu'])!r}"]
    for side, kind in KINDS.items():
        L += ["", "[[boundary]]", f'name = "{side}"', f'kind = "{kind}"']
        if kind == "neumann":
            L.append(f'traction = ["{st[f"g_{side}_1"]}", "{st[f"g_{side}_2"]}"]')
        if kind == "dirichlet":
            L.append(f'u = ["{st[f"uD_{side}_1"]}", "{st[f"uD_{side}_2"]}"]')
        if kind == "contact":
            L.append(f'g_a  = "{st["g_a"]}"')
    L += ["", "[loads]", f'f = ["{st["f1"]}", "{st["f2"]}"]', "", "[initial]", f'u0 = ["{st["u0_1"]}", "{st["u0_2"]}"]',
          "", "[time]", f"T = {float(d['T'])!r}", f"steps = {d['steps']}", "", "[discretisation]", "rho = 10.0",
          "", "[solver]", 'method   = "ssn"', "tol      = 1e-12", "max_iter = 500", "", "[exact]",
          f'u    = ["{st["u1"]}", "{st["u2"]}"]',
          f'grad = [["{st["grad11"]}", "{st["grad12"]}"],\n        ["{st["grad21"]}", "{st["grad22"]}"]]', ""]
    return "\n".join(L)


def check_toml(text, d):
    """The scene text parses as TOML and carries exactly the derived strings."""
    import tomllib
    doc = tomllib.loads(text)
    st = d["str"]
    require(doc["exact"]["u"] == [st["u1"], st["u2"]] and doc["loads"]["f"] == [st["f1"], st["f2"]],
            "mms_lshape: TOML exact.u or f mismatch")
    parts_ = {b["name"]: b for b in doc["boundary"]}
    require(all(parts_[s]["kind"] == k for s, k in KINDS.items()), "mms_lshape: TOML boundary kinds mismatch")

"""Checks of a derived manufactured case: the printed strings read back (by ``tresca_py.expr``, the reading
the solvers share) equal the sympy originals; grad, f, u0 and the tractions agree with independent finite
differences; the Tresca conditions hold pointwise on Gamma_C on a fine space-time grid."""
import subprocess

import numpy as np
import sympy as sp

from tresca_py.expr import parse, symbols
from tresca_py.mms.blocks import lam
from tresca_py.mms.derive import derive, require
from tresca_py.mms.elasticity import body_force, stress
from tresca_py.mms.tresca_law import check_tresca_law, np_grad, side_grid, stress_np

x, y, t = symbols()

def sample_points(d, rng, n=400):
    """Random points of the (possibly rotated) quadrilateral, or of ``d["region"](rng, n)`` where a case
    gives its own sampler, and random times in [0, T]."""
    if "region" in d:
        X, Y = d["region"](rng, n)
        return X, Y, rng.random(n) * float(d["T"])
    c = np.array([[float(v) for v in p] for p in d["corners"]])
    a, b = rng.random(n), rng.random(n)
    P = ((1 - a) * (1 - b))[:, None] * c[0] + (a * (1 - b))[:, None] * c[1] + \
        (a * b)[:, None] * c[2] + ((1 - a) * b)[:, None] * c[3]
    T = rng.random(n) * float(d["T"])
    return P[:, 0], P[:, 1], T


def check_roundtrip(d, rng, log):
    """Printed string == sympy original at random points (strings re-parsed into sympy Max/Min)."""
    X, Y, T = sample_points(d, rng, 600)
    d["parsed"] = {}
    for k, s in d["str"].items():
        p = parse(s, k)
        d["parsed"][k] = p
        a, b = lam(d["sym"][k])(X, Y, T), lam(p)(X, Y, T)
        scale = max(1.0, np.max(np.abs(a)))
        err = np.max(np.abs(a - b)) / scale
        require(err < 1e-13, "%s: round trip of %s differs by %.3e" % (d["name"], k, err))
    log("round trip of %d printed expressions (max/min re-parsed)      ok" % len(d["str"]))


def check_exmex_binary(d, rng, binary, log):
    """Evaluate every printed string with a real exmex binary (reads 'expr\\tt\\tx\\ty' lines)."""
    X, Y, T = sample_points(d, rng, 40)
    lines, refs = [], []
    for k, s in d["str"].items():
        ref = lam(d["sym"][k])(X, Y, T)
        for i in range(len(X)):
            lines.append("%s\t%r\t%r\t%r" % (s, float(T[i]), float(X[i]), float(Y[i])))
            refs.append((k, ref[i]))
    out = subprocess.run([binary], input="\n".join(lines) + "\n", capture_output=True, text=True,
                         check=True).stdout.split("\n")
    worst = 0.0
    for (k, ref), o in zip(refs, out, strict=False):
        require(not o.startswith("ERR"), "%s: exmex rejects %s: %s" % (d["name"], k, o))
        worst = max(worst, abs(float(o) - ref) / max(1.0, abs(ref)))
    require(worst < 1e-12, "%s: exmex evaluation differs by %.3e" % (d["name"], worst))
    log("exmex binary evaluates all %d strings (max rel diff %.1e)        ok" % (len(d["str"]), worst))


def check_derivatives(d, rng, log):
    """Independent finite-difference checks of the printed data: grad vs FD of u, f vs -div sigma(FD),
    u0 = u(.,0), Neumann traction = sigma(grad) n, all using the re-parsed strings."""
    check_fields(d, rng)
    check_sides(d)
    log("grad = FD(u), f = -div sigma (FD and symbolic), u0, g = sigma n, u = 0 on Gamma_D   ok")


def check_fields(d, rng):
    """grad vs FD of u, f vs -div sigma (FD of the printed grad, and symbolically), u0 = u(., 0) at the
    sample points (re-parsed strings)."""
    P = d["parsed"]
    lam_, mu = float(d["lam"]), float(d["mu"])
    X, Y, T = sample_points(d, rng, 400)
    u = [lam(P["u1"]), lam(P["u2"])]
    Gf = np_grad(d)
    h = 1e-6
    worst = 0.0
    for i in range(2):
        for j, (dx, dy) in enumerate([(h, 0), (0, h)]):
            fd = (u[i](X + dx, Y + dy, T) - u[i](X - dx, Y - dy, T)) / (2 * h)
            g = Gf[i][j](X, Y, T)
            worst = max(worst, np.max(np.abs(fd - g)) / max(1e-2, np.max(np.abs(g))))
    require(worst < 1e-6, "%s: grad != FD of u (%.2e)" % (d["name"], worst))
    # f = -div sigma with sigma from the printed grad, by central differences
    h = 1e-5
    def sig(Xp, Yp):
        return stress_np(Gf, lam_, mu, Xp, Yp, T)
    sxp, sxm, syp, sym_ = sig(X + h, Y), sig(X - h, Y), sig(X, Y + h), sig(X, Y - h)
    div1 = (sxp[0] - sxm[0]) / (2 * h) + (syp[1] - sym_[1]) / (2 * h)
    div2 = (sxp[1] - sxm[1]) / (2 * h) + (syp[2] - sym_[2]) / (2 * h)
    f1, f2 = lam(P["f1"])(X, Y, T), lam(P["f2"])(X, Y, T)
    scale = max(1e-2, np.max(np.abs(f1)), np.max(np.abs(f2)))
    err = max(np.max(np.abs(f1 + div1)), np.max(np.abs(f2 + div2))) / scale
    require(err < 1e-5, "%s: equilibrium f + div sigma = %.2e (FD)" % (d["name"], err))
    # exact (symbolic) equilibrium with the parsed expressions
    lam_s, mu_s = d["lam"], d["mu"]
    Gp = sp.Matrix([[P["grad11"], P["grad12"]], [P["grad21"], P["grad22"]]])
    Sp = stress(Gp, lam_s, mu_s)
    fr = body_force(Sp)
    res = max(np.max(np.abs(lam(fr[0] - P["f1"])(X, Y, T))), np.max(np.abs(lam(fr[1] - P["f2"])(X, Y, T))))
    require(res < 1e-11 * scale, "%s: symbolic equilibrium residual %.2e" % (d["name"], res))
    # u0
    Z = np.zeros_like(X)
    e0 = max(np.max(np.abs(lam(P["u0_1"])(X, Y, Z) - u[0](X, Y, Z))),
             np.max(np.abs(lam(P["u0_2"])(X, Y, Z) - u[1](X, Y, Z))))
    require(e0 < 1e-14, "%s: u0 != u(.,0)" % d["name"])


def check_sides(d):
    """Neumann traction = sigma(grad) n and u = 0 on Gamma_D along the quadrilateral's sides."""
    P = d["parsed"]
    lam_, mu = float(d["lam"]), float(d["mu"])
    u = [lam(P["u1"]), lam(P["u2"])]
    Gf = np_grad(d)
    s = np.linspace(0, 1, 201)
    tt = np.linspace(0, float(d["T"]), 21)
    for side, kind in d["kinds"].items():
        PX, PY, TT, n, _ = side_grid(d["corners"], side, s, tt)
        if kind == "neumann":
            s11, s12, s22 = stress_np(Gf, lam_, mu, PX, PY, TT)
            g1 = lam(P["g_%s_1" % side])(PX, PY, TT)
            g2 = lam(P["g_%s_2" % side])(PX, PY, TT)
            err = max(np.max(np.abs(s11 * n[0] + s12 * n[1] - g1)), np.max(np.abs(s12 * n[0] + s22 * n[1] - g2)))
            require(err < 1e-12 * max(1, np.max(np.abs(g1)), np.max(np.abs(g2))),
                    "%s: traction on %s != sigma n (%.2e)" % (d["name"], side, err))
        if kind == "dirichlet":
            err = max(np.max(np.abs(u[0](PX, PY, TT))), np.max(np.abs(u[1](PX, PY, TT))))
            require(err < 1e-13, "%s: u != 0 on Dirichlet side %s (%.2e)" % (d["name"], side, err))


def check_contact(d, log):
    """Pointwise Tresca conditions on every contact side (u.n = 0 there) on a fine space-time grid, with the
    times of ``d["t_special"]`` and either side of them (tresca_py.mms.tresca_law)."""
    times = sample_times(d, 601)
    for side in [s for s, k in d["kinds"].items() if k == "contact"]:
        check_tresca_law(d, side, np.linspace(0, 1, 2001), times, log=log)


def sample_times(d, n):
    """``n`` equidistant times of [0, T] plus the times of ``d["t_special"]`` and either side of them."""
    times = set(np.linspace(0, float(d["T"]), n).tolist())
    for ts in d.get("t_special", []):
        times |= {float(ts) - 1e-9, float(ts), float(ts) + 1e-9}
    return np.array(sorted(times))


def run_checks(case, exmex_bin=None, log=print):
    rng = np.random.default_rng(20240611)          # fixed seed: deterministic
    d = derive(case)
    check_roundtrip(d, rng, log)
    if exmex_bin:
        check_exmex_binary(d, rng, exmex_bin, log)
    check_derivatives(d, rng, log)
    check_contact(d, log)
    return d

#!/usr/bin/env python3
"""Manufactured cases with nonzero boundary data (scene keys `u` of a dirichlet part, `gap` of a
contact part; issue 30). Run from this folder:

    ../../.venv/bin/python cases_boundary.py            # derive, check, write ../cases/mms_data_*.toml
    ../../.venv/bin/python cases_boundary.py --check    # derive and check only

It reuses derive.py's printer, parser and building blocks (imported, not edited) and adds:

* the Dirichlet data u_D = u on every dirichlet side and the gap g_n = u.n on Gamma_C, printed and
  round-tripped like every other string;
* checks that u_D equals u on Gamma_D and g_n equals u.n on Gamma_C (pointwise, space-time grid);
* the Tresca law on Gamma_C with u.n = g_n (not 0): |sigma_t| <= g_a, stick where |sigma_t| < g_a,
  slip velocity opposite to sigma_t where slipping; for the static case (b) the law of its one
  backward-Euler step from u0 = 0 (slip increment u_t(1) opposite to sigma_t(1), |sigma_t| = g_a where
  it is nonzero);
* a self-test: a flipped friction sign, a wrong bound and a wrong gap must each be caught.

Cases:
(a) mms_data_front: mms_front's travelling stick-slip pulse on the bottom side, plus a normal
    displacement g(x,t) on Gamma_C and nonzero values on the Dirichlet top side y = 1.
(c) mms_data_stop: derive.py's mms_stop (the O(k) case) with the same kind of data as (a).
(b) mms_data_cep: the Tresca solution of Chouly, Ern & Pignet (SIAM J. Sci. Comput. 2020):
    Omega = (0,1)^2, Gamma_C = {y = 0}, u = (x e^{xy}(1 + 1/(1+lam)), y e^{xy}(-1 + 1/(1+lam)))/6,
    mu = 2, lam = 2e4, g_a = s(x) = mu x^2 (lam/2 + 1)/(3 lam + 3), the three other sides Dirichlet
    with u. Static: the scene makes it one backward-Euler step from u0 = 0 at t = 0 to t = 1 with all
    data scaled by t, which solves exactly the static Tresca problem at t = 1.
"""

import argparse
import pathlib
import sys

import numpy as np
import sympy as sp

import derive as D
from derive import R, x, y, t, Xs, Ys, SStep, lam, require, side_geometry, CheckFailed

HERE = pathlib.Path(__file__).resolve().parent
CASES_DIR = HERE.parent / "cases"


def case_data_front(slip_sign=1, gap_scale=1, ga_scale=1):
    """(a): mms_front with u.n = g_n != 0 on Gamma_C and u != 0 on Gamma_D.

    Local construction (derive.py section 5) with U2(X,0) = g(X,t) != 0: sigma_t.tau = -mu (dU1/dY +
    dU2/dX) at Y = 0, so the phi1 coefficient carries -g_X to keep the prescribed traction lam_t:
        U1 = phi0 s + phi1 (-lam_t/mu - g_X) + Y^2 (1-Y) r + Y^2 h,   U2 = Y (1-Y) w + g,
    h(X,t) = (1+t) sin(X)/20 makes u1 != 0 on the top side, g makes u2 != 0 there and on Gamma_C."""
    E, nu = R(10), R(3, 10)
    lam_, mu = D.lame(E, nu)
    g0, A, w = R(1, 5), R(1, 20), R(1, 2)
    xi = R(1, 4) + R(1, 2) * t
    ga = ga_scale * g0 * (1 + Xs / 2)
    s = slip_sign * A * SStep((xi - Xs) / w, 0)
    delta = R(1, 4)
    lam_t = -g0 * (1 + Xs / 2) + R(3, 2) * g0 * (SStep((Xs - xi) / delta, 0) + SStep((xi - w - Xs) / delta, 0))
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    g = (1 + Xs / 2) * (1 + t) / 40
    h = (1 + t) * sp.sin(Xs) / 20
    U1 = D.PHI0 * s + D.PHI1 * (-lam_t / mu - sp.diff(g, Xs)) + Ys ** 2 * (1 - Ys) * r + Ys ** 2 * h
    U2 = Ys * (1 - Ys) * wv + g
    u, _ = D.to_global(U1, U2, 1, 0)
    case = dict(
        name="mms_data_front",
        title="MMS (issue 30 a): travelling stick-slip pulse with imposed normal displacement and Dirichlet data",
        header="""\
mms_front (travelling slip pulse on Gamma_C = bottom side y = 0, fronts in both directions) with boundary data:
  normal displacement on Gamma_C  u.n = -u2(x,0,t) = -g(x,t),  g = (1 + x/2)(1 + t)/40   (contact `gap`)
  Dirichlet data on the top side  u(x,1,t) = ((1+t) sin(x)/20, g(x,t))                  (dirichlet `u`)
  u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu - g_x) + y^2(1-y)(1+t)cos(x)/20 + y^2 (1+t) sin(x)/20,
  u2 = y(1-y)(1+x)(1+t/2)/20 + g,   s, sigma_t.tau, g_a, phi0, phi1 as in mms_front (E = 10, nu = 0.3).
  The -g_x term keeps sigma_t.tau = -mu(du1/dy + du2/dx) at y = 0 as prescribed, so the Tresca data are
  those of mms_front: slip zone xi(t) - 1/2 < x < xi(t), xi = 1/4 + t/2, slip in +x, sigma_t.tau = -g_a there.
u(.,t) is smooth (C^2 in the front variable): expected energy/H1 error O(h), L2 error O(h^2).
Derivation and pointwise checks: verification/mms/cases_boundary.py.""",
        E=E, nu=nu, corners=D.UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=64,
        expect={"stick_to_slip": True, "slip_to_stick": True}, static=False)
    if gap_scale != 1:
        case["gap_scale"] = gap_scale
    return case


def case_data_cep(ga_scale=1):
    """(b): Chouly-Ern-Pignet's Tresca solution, static, as one step from u0 = 0 (data scaled by t)."""
    mu = R(2)
    lam_ = R(20000)
    E = mu * (3 * lam_ + 2 * mu) / (lam_ + mu)
    nu = lam_ / (2 * (lam_ + mu))
    c = 1 / (1 + lam_)
    u_static = [x * sp.exp(x * y) * (1 + c) / 6, y * sp.exp(x * y) * (-1 + c) / 6]
    ga = ga_scale * mu * x ** 2 * (lam_ / 2 + 1) / (3 * lam_ + 3)
    u = [t * u_static[0], t * u_static[1]]
    return dict(
        name="mms_data_cep",
        title="MMS (issue 30 b): Chouly-Ern-Pignet Tresca solution, near-incompressible (lam = 2e4, mu = 2)",
        header="""\
Chouly, Ern & Pignet (SIAM J. Sci. Comput. 2020), Tresca friction, near-incompressible locking test:
  Omega = (0,1)^2, Gamma_C = {y = 0}, the three other sides Dirichlet with u,
  u = (x e^{xy}(1 + 1/(1+lam)), y e^{xy}(-1 + 1/(1+lam)))/6,  mu = 2, lam = 2e4
  (E = mu(3 lam + 2 mu)/(lam + mu), nu = lam/(2(lam + mu))),
  g_a = s(x) = mu x^2 (lam/2 + 1)/(3 lam + 3): sigma_t.tau = -mu x^2 (lam+2)/(6(lam+1)) = -s(x) on y = 0,
  the whole of Gamma_C slips (u.tau = x(1 + 1/(1+lam))/6 > 0), u.n = 0 there.
Static problem: one backward-Euler step from u0 = 0 at t = 0 to t = 1 with f, u_D and the exact u scaled
by t, which is exactly the static Tresca problem at t = 1 (j_h(u - u0) = j_h(u)). The time grid has one
step by construction: only h rates are meaningful.
Expected: energy/H1 error O(h), L2 error O(h^2), uniformly in lam (CR with the jump stabilisation is
locking-free). Derivation and pointwise checks: verification/mms/cases_boundary.py.""",
        E=E, nu=nu, corners=D.UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "dirichlet", "top": "dirichlet", "left": "dirichlet"},
        u=u, g_a=ga, T=1, steps=1, expect={}, static=True)


def case_data_stop():
    """(c): derive.py's mms_stop (slip stops abruptly at t* = 1/3: the O(k) case) plus the data field
    v = (y^2 h - phi1(y) g_x, g) of (a): v = (0, g) on y = 0 and d v1/dy + d v2/dx = 0 there, so v leaves
    the slip and sigma_t.tau of mms_stop unchanged and adds u.n = -g on Gamma_C and v(x,1) != 0 on the
    Dirichlet top side."""
    c = D.case_stop()
    g = (1 + x / 2) * (1 + t) / 40
    h = (1 + t) * sp.sin(x) / 20
    phi1 = y * (1 - y) ** 2
    v = [y ** 2 * h - phi1 * sp.diff(g, x), g]
    c = dict(c, u=[c["u"][0] + v[0], c["u"][1] + v[1]], name="mms_data_stop", static=False,
             title="MMS (issue 30 c): slip stops abruptly at t* = 1/3, with Dirichlet data and imposed normal displacement")
    c["header"] = c["header"].split("\nMeasured errors")[0] + """
Plus boundary data (issue 30): u + v with v = (y^2 (1+t) sin(x)/20 - y(1-y)^2 g_x, g), g = (1 + x/2)(1 + t)/40:
v = (0, g) on y = 0 and dv1/dy + dv2/dx = 0 there, so slip and sigma_t.tau are mms_stop's, u.n = -g on
Gamma_C (contact `gap`) and u(x,1,t) != 0 on the top side (dirichlet `u`).
Derivation and pointwise checks: verification/mms/cases_boundary.py."""
    return c


CASES = [case_data_front, case_data_cep, case_data_stop]


def derive_data(case):
    """derive.derive, plus the printed data strings u_D (per dirichlet side) and the gap."""
    d = D.derive(case)
    u = d["u"]
    for side, kind in case["kinds"].items():
        if kind == "dirichlet":
            d["sym"]["uD_%s_1" % side], d["sym"]["uD_%s_2" % side] = u[0], u[1]
        if kind == "contact":
            n = D.side_normal_exact(case["corners"], side)
            d["sym"]["gap_%s" % side] = sp.simplify(u[0] * n[0] + u[1] * n[1]) * case.get("gap_scale", 1)
    d["str"] = {k: D.ex(v) for k, v in d["sym"].items()}
    for k, v in d["str"].items():
        problems = D.exmex_lint(v)
        if problems:
            raise CheckFailed("%s: %s violates exmex syntax rules: %s" % (case["name"], k, problems))
    return d


def grid(d, side, ns=1001, nt=401):
    a, b, n, tau = side_geometry(d["corners"], side)
    s = np.linspace(0, 1, ns)
    times = np.array([float(d["T"])]) if d["static"] else np.linspace(0, float(d["T"]), nt)
    S_, TT = np.meshgrid(s, times, indexing="ij")
    return a[0] + S_ * (b[0] - a[0]), a[1] + S_ * (b[1] - a[1]), TT, n, tau


def check_data(d, log):
    """u_D = u on Gamma_D and gap = u.n on Gamma_C (parsed strings, space-time grid); u0 = u(., 0)
    agrees with the data at t = 0 by construction (it is u(., 0))."""
    P = d["parsed"]
    u = [lam(P["u1"]), lam(P["u2"])]
    for side, kind in d["kinds"].items():
        PX, PY, TT, n, _ = grid(d, side, 201, 21)
        if kind == "dirichlet":
            err = max(np.max(np.abs(lam(P["uD_%s_%d" % (side, c + 1)])(PX, PY, TT) - u[c](PX, PY, TT))) for c in range(2))
            require(err < 1e-13, "%s: u_D != u on %s (%.2e)" % (d["name"], side, err))
        if kind == "contact":
            un = u[0](PX, PY, TT) * n[0] + u[1](PX, PY, TT) * n[1]
            err = np.max(np.abs(lam(P["gap_%s" % side])(PX, PY, TT) - un))
            require(err < 1e-13, "%s: gap != u.n on %s (%.2e)" % (d["name"], side, err))
            require(np.max(np.abs(un)) > 0 or d["static"], "%s: the gap is zero" % d["name"])
    log("u_D = u on Gamma_D, gap = u.n on Gamma_C                          ok")


def check_tresca(d, log):
    """Tresca's law on Gamma_C with u.n = gap (continuous in time for (a), the one BE step for (b))."""
    P = d["parsed"]
    lam_, mu = float(d["lam"]), float(d["mu"])
    Gf = D.np_grad(d)
    side = [s for s, k in d["kinds"].items() if k == "contact"][0]
    PX, PY, TT, n, tau = grid(d, side)
    s11, s12, s22 = D.stress_np(Gf, lam_, mu, PX, PY, TT)
    sn1, sn2 = s11 * n[0] + s12 * n[1], s12 * n[0] + s22 * n[1]
    snn = sn1 * n[0] + sn2 * n[1]
    st1, st2 = sn1 - snn * n[0], sn2 - snn * n[1]
    st_abs = np.hypot(st1, st2)
    ga = lam(P["g_a"])(PX, PY, TT)
    if d["static"]:
        # the increment of the one step: u(., 1) - u0, u0 = 0
        v1, v2 = lam(P["u1"])(PX, PY, TT), lam(P["u2"])(PX, PY, TT)
    else:
        v1, v2 = lam(sp.diff(P["u1"], t))(PX, PY, TT), lam(sp.diff(P["u2"], t))(PX, PY, TT)
    vn = v1 * n[0] + v2 * n[1]
    vt1, vt2 = v1 - vn * n[0], v2 - vn * n[1]
    vt_abs = np.hypot(vt1, vt2)
    ttol = 1e-11 * np.max(ga)
    vtol = 1e-11 * max(1e-3, np.max(vt_abs))
    require(np.max(st_abs - ga) <= ttol, "%s: |sigma_t| exceeds g_a by %.2e" % (d["name"], np.max(st_abs - ga)))
    stick = st_abs < ga - ttol
    bad = np.max(vt_abs[stick]) if stick.any() else 0.0
    require(bad <= vtol, "%s: stick point with slip velocity %.2e" % (d["name"], bad))
    slip = vt_abs > vtol
    require(slip.mean() > 0.05, "%s: (almost) no slip samples" % d["name"])
    gap = np.max(np.abs(st_abs[slip] - ga[slip]))
    require(gap <= ttol, "%s: slipping point with |sigma_t| != g_a (%.2e)" % (d["name"], gap))
    theta = -(vt1 * st1 + vt2 * st2)[slip] / st_abs[slip] ** 2
    require(np.min(theta) >= 0, "%s: slip velocity not opposite to sigma_t" % d["name"])
    res = np.max(np.hypot(vt1[slip] + theta * st1[slip], vt2[slip] + theta * st2[slip]))
    require(res <= vtol, "%s: u_t' not parallel to sigma_t (%.2e)" % (d["name"], res))
    if not d["static"]:
        require(stick.mean() > 0.05, "%s: (almost) no stick samples" % d["name"])
        dsl = np.diff(slip.astype(int), axis=1)
        exp = d["expect"]
        require(np.any(dsl == 1) == exp["stick_to_slip"] and np.any(dsl == -1) == exp["slip_to_stick"],
                "%s: stick/slip transitions not as expected" % d["name"])
        require(np.max(st_abs[:, 0] - ga[:, 0]) <= ttol, "%s: u0 incompatible" % d["name"])
    # the sign, with sympy: sigma_t.tau = -g_a and u.tau increasing where slipping (printed numbers)
    st_tau = st1 * tau[0] + st2 * tau[1]
    log("Tresca on %s with u.n = gap: |sig_t|<=g_a, stick, slip opposite sig_t   ok  (stick %.0f%%, slip %.0f%%, "
        "sigma_t.tau in [%.3g, %.3g], max |u.n| %.3g)" % (side, 100 * stick.mean(), 100 * slip.mean(),
                                                          st_tau.min(), st_tau.max(), np.max(np.abs(vn if d["static"] else lam(P["u2"])(PX, PY, TT)))))


def check_cep_symbolic(log):
    """Chouly-Ern-Pignet with sympy: sigma_t.tau = -s(x) exactly on y = 0 and u.tau > 0 for x > 0."""
    mu, lm = sp.Symbol("mu", positive=True), sp.Symbol("lam", positive=True)
    c = 1 / (1 + lm)
    u = [x * sp.exp(x * y) * (1 + c) / 6, y * sp.exp(x * y) * (-1 + c) / 6]
    s12 = mu * (sp.diff(u[0], y) + sp.diff(u[1], x))
    # n = (0, -1), tau = (1, 0): sigma_t.tau = (sigma n).tau = -sigma_12
    st_tau = sp.simplify(-s12.subs(y, 0))
    s = mu * x ** 2 * (lm / 2 + 1) / (3 * lm + 3)
    require(sp.simplify(st_tau + s) == 0, "CEP: sigma_t.tau != -s(x) on y = 0: %s" % st_tau)
    require(sp.simplify(u[1].subs(y, 0)) == 0, "CEP: u.n != 0 on y = 0")
    require(sp.simplify(u[0].subs(y, 0) - x * (lm + 2) / (6 * (lm + 1))) == 0, "CEP: u.tau on y = 0")
    log("CEP (sympy, symbolic mu, lam): sigma_t.tau = -s(x), u.n = 0, u.tau = x(lam+2)/(6(lam+1)) > 0   ok")


def run_checks(case, log=print):
    rng = np.random.default_rng(20261126)
    d = derive_data(case)
    D.check_roundtrip(d, rng, log)
    # derive's derivative checks, with the dirichlet sides (nonzero here) checked by check_data instead
    d2 = dict(d, kinds={k: ("neumann" if v == "neumann" else "other") for k, v in d["kinds"].items()})
    D.check_derivatives(d2, rng, log)
    check_data(d, log)
    check_tresca(d, log)
    return d


def selftest():
    """Wrong data must be caught: flipped friction sign, bound 1% off, wrong gap. (Flipping the CEP
    slip flips its traction with it: that is a solution too, so (b)'s mutant is a wrong bound.)"""
    mutants = {
        "(a) slip along sigma_t": lambda: case_data_front(slip_sign=-1),
        "(a) g_a 1% too small": lambda: case_data_front(ga_scale=R(99, 100)),
        "(a) gap of the wrong size": lambda: case_data_front(gap_scale=R(11, 10)),
        "(b) g_a 1% too large (slip below the bound)": lambda: case_data_cep(ga_scale=R(101, 100)),
    }
    for what, make in mutants.items():
        try:
            run_checks(make(), log=lambda msg: None)
        except CheckFailed as err:
            print("   selftest: %-35s caught: %s" % (what, err))
            continue
        raise CheckFailed("selftest: mutant '%s' passed the checks" % what)


def write_toml(d, path):
    st = d["str"]
    text = D.write_toml(d, path)
    # the data keys: after each part's kind line
    lines = text.split("\n")
    out = []
    side = None
    for line in lines:
        out.append(line)
        if line.startswith("name = "):
            side = line.split('"')[1]
        if line.startswith("kind = ") and side is not None:
            kind = d["kinds"][side]
            if kind == "dirichlet":
                out.append('u = ["%s", "%s"]' % (st["uD_%s_1" % side], st["uD_%s_2" % side]))
            if kind == "contact":
                out.append('gap = "%s"' % st["gap_%s" % side])
    text = "\n".join(out).replace("GENERATED by verification/mms/derive.py", "GENERATED by verification/mms/cases_boundary.py")
    text = text.replace("# Regenerate: .venv/bin/python verification/mms/derive.py",
                        "# Regenerate: cd verification/mms && ../../.venv/bin/python cases_boundary.py")
    path.write_text(text)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true")
    args = ap.parse_args()
    derived = []
    try:
        check_cep_symbolic(print)
        for make in CASES:
            case = make()
            print("== %s: %s" % (case["name"], case["title"]))
            derived.append(run_checks(case, lambda m: print("   " + m)))
        print("== selftest: deliberately wrong data must be rejected")
        selftest()
    except (CheckFailed, D.NotPrintable) as err:
        print("\nCHECK FAILED: %s" % err, file=sys.stderr)
        sys.exit(1)
    if args.check:
        print("all checks passed (nothing written)")
        return
    for d in derived:
        path = CASES_DIR / (d["name"] + ".toml")
        write_toml(d, path)
        D.check_toml(path, d)
        print("wrote %s" % path)
    print("all checks passed")


if __name__ == "__main__":
    main()

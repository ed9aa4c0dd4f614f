"""Manufactured cases with nonzero boundary data (scene keys `u` of a dirichlet part, `gap` of a contact
part): verification/cases/mms_data_*.toml. The data strings and checks are tresca_py.mms.boundary_checks.

(a) mms_data_front: mms_front's travelling stick-slip pulse on the bottom side, plus a normal
    displacement g(x,t) on Gamma_C and nonzero values on the Dirichlet top side y = 1.
(c) mms_data_stop: mms_stop (the O(k) case) with the same kind of data as (a).
(b) mms_data_cep: the Tresca solution of Chouly, Ern & Pignet (SIAM J. Sci. Comput. 2020):
    Omega = (0,1)^2, Gamma_C = {y = 0}, u = (x e^{xy}(1 + 1/(1+lam)), y e^{xy}(-1 + 1/(1+lam)))/6,
    mu = 2, lam = 2e4, g_a = s(x) = mu x^2 (lam/2 + 1)/(3 lam + 3), the three other sides Dirichlet
    with u. Static: the scene makes it one backward-Euler step from u0 = 0 at t = 0 to t = 1 with all
    data scaled by t, which solves exactly the static Tresca problem at t = 1.
"""
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.mms.blocks import SStep
from tresca_py.mms.cases import UNIT_SQUARE, case_stop
from tresca_py.mms.derive import require
from tresca_py.elastic import lame
from tresca_py.mms.elasticity import PHI0, PHI1, Xs, Ys, to_global

x, y, t = symbols()
R = sp.Rational


def case_data_front(slip_sign=1, gap_scale=1, ga_scale=1):
    """(a): mms_front with u.n = g_n != 0 on Gamma_C and u != 0 on Gamma_D.

    Local construction (tresca_py.mms.elasticity.local_field) with U2(X,0) = g(X,t) != 0: sigma_t.tau = -mu (dU1/dY +
    dU2/dX) at Y = 0, so the phi1 coefficient carries -g_X to keep the prescribed traction lam_t:
        U1 = phi0 s + phi1 (-lam_t/mu - g_X) + Y^2 (1-Y) r + Y^2 h,   U2 = Y (1-Y) w + g,
    h(X,t) = (1+t) sin(X)/20 makes u1 != 0 on the top side, g makes u2 != 0 there and on Gamma_C."""
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
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
    U1 = PHI0 * s + PHI1 * (-lam_t / mu - sp.diff(g, Xs)) + Ys ** 2 * (1 - Ys) * r + Ys ** 2 * h
    U2 = Ys * (1 - Ys) * wv + g
    u, _ = to_global(U1, U2, 1, 0)
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
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
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
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "dirichlet", "top": "dirichlet", "left": "dirichlet"},
        u=u, g_a=ga, T=1, steps=1, expect={}, static=True)


def case_data_stop():
    """(c): mms_stop (tresca_py.mms.cases) (slip stops abruptly at t* = 1/3: the O(k) case) plus the data field
    v = (y^2 h - phi1(y) g_x, g) of (a): v = (0, g) on y = 0 and d v1/dy + d v2/dx = 0 there, so v leaves
    the slip and sigma_t.tau of mms_stop unchanged and adds u.n = -g on Gamma_C and v(x,1) != 0 on the
    Dirichlet top side."""
    c = case_stop()
    g = (1 + x / 2) * (1 + t) / 40
    h = (1 + t) * sp.sin(x) / 20
    phi1 = y * (1 - y) ** 2
    v = [y ** 2 * h - phi1 * sp.diff(g, x), g]
    c = dict(c, u=[c["u"][0] + v[0], c["u"][1] + v[1]], name="mms_data_stop", static=False,
             title="MMS (issue 30 c): slip stops abruptly at t* = 1/3, with Dirichlet data and imposed normal "
                   "displacement")
    c["header"] = c["header"].split("\nMeasured errors")[0] + """
Plus boundary data (issue 30): u + v with v = (y^2 (1+t) sin(x)/20 - y(1-y)^2 g_x, g), g = (1 + x/2)(1 + t)/40:
v = (0, g) on y = 0 and dv1/dy + dv2/dx = 0 there, so slip and sigma_t.tau are mms_stop's, u.n = -g on
Gamma_C (contact `gap`) and u(x,1,t) != 0 on the top side (dirichlet `u`).
Derivation and pointwise checks: verification/mms/cases_boundary.py."""
    return c


CASES = [case_data_front, case_data_cep, case_data_stop]


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

"""Manufactured Signorini-Tresca and Signorini-Coulomb solutions (issue 40): verification/cases/mms_signorini_*.toml.

Unit square, Gamma_C = bottom side y = 0 (n = (0,-1), tau = (1,0): u.n = -u2(x,0), u.tau = u1(x,0)), clamped top,
Neumann left/right. The construction separates what the laws constrain from what they do not:

* on Gamma_C the exact displacement has  u.n = g - q,  q = B max(0, x - a(t))^3 >= 0,  and  u.tau = s(x,t);
* the exact contact reaction is  r = -p n + lt tau  with the pressure  p = P0 max(0, a(t) - x)^2 >= 0,
  so  p (u.n - g) = 0: contact where x < a(t), separated where x > a(t) (the contact/separation point a(t));
* (s, lt) satisfy the friction law: Tresca (|lt| <= g_a on all of Gamma_C) or Coulomb (|lt| <= F p);
* the given surface load on Gamma_C (contact `traction`) is  sigma(u) n - r,  f = -div sigma(u), the Neumann
  data sigma(u) n, u0 = u(., 0).

So u itself may be any smooth field with these two traces; its regularity is that of the power blocks:
u(., t) is C^2 with piecewise smooth third derivatives (W^{3,inf}, in H^{3}), p is C^1 on Gamma_C, the gap
opens like (x - a)^3. The chosen fronts move monotonically: every point whose slip increment over
(t_{n-1}, t_n] is nonzero slips at t_n, and the normal law has no history, so u satisfies every backward-Euler
step exactly: no time error (the errors are independent of N). Predicted orders: energy / broken H1 O(h),
L2 O(h^2) (the smooth-solution orders of the stabilised CR element; no k-error).
"""
import sympy as sp

from tresca_py.elastic import lame
from tresca_py.expr import symbols
from tresca_py.mms.blocks import PosPow, SStep
from tresca_py.mms.cases import UNIT_SQUARE
from tresca_py.mms.elasticity import PHI0, PHI1, Xs, Ys

x, y, t = symbols()
R = sp.Rational

KINDS = {"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"}
A_OF_T = R(3, 5) + R(1, 5) * t          # contact/separation point: contact x < a(t), separated x > a(t)
XI_OF_T = R(1, 5) + R(2, 5) * t         # stick/slip point: slip x < xi(t), stick x > xi(t)
GAP = (2 + x) * (1 + t) / 100           # the gap g(x, t): u.n <= g
B_OPEN, P0, A_SLIP, G0 = R(1, 2), R(1), R(1, 10), R(1, 5)


def contact_traces(slip_power=3):
    """(u.n, p, s) on Gamma_C as functions of x, t: u.n = g - B (x-a)_+^3, p = P0 (a-x)_+^2,
    s = A (xi-x)_+^slip_power."""
    a, xi = A_OF_T, XI_OF_T
    return GAP - B_OPEN * PosPow(x - a, 3), P0 * PosPow(a - x, 2), A_SLIP * PosPow(xi - x, slip_power)


def general_field(un, s, lt, mu):
    """A displacement with u.n = un and u.tau = s on y = 0, zero on y = 1 (cubic Hermite profiles in y), whose
    sigma(u)n . tau on Gamma_C is lt - mu d(u2)/dx (the tangential load then only carries that term)."""
    sub = {Xs: x, Ys: y}
    ph0, ph1 = PHI0.subs(sub), PHI1.subs(sub)
    u2 = ph0 * (-un) + y * (1 - y) * (1 + x) * (1 + t / 2) / 20
    u1 = ph0 * s + ph1 * (-lt / mu) + y ** 2 * (1 - y) * (1 + t) * sp.cos(x) / 20
    return [u1, u2]


def divfree_field(un, s):
    """u = curl psi = (psi_y, -psi_x), div u = 0 exactly: psi = phi0(y) Psi0 + phi1(y) s + y^2 (1-y)^2 R with
    d(Psi0)/dx = un, so u.n = -u2(x,0) = un, u.tau = u1(x,0) = s, and u = 0 on y = 1."""
    sub = {Xs: x, Ys: y}
    psi0 = sp.integrate(GAP, x) - B_OPEN * PosPow(x - A_OF_T, 4) / 4
    assert sp.simplify(sp.diff(psi0, x) - un) == 0
    psi = PHI0.subs(sub) * psi0 + PHI1.subs(sub) * s + y ** 2 * (1 - y) ** 2 * (1 + t) * sp.sin(x) / 20
    return [sp.diff(psi, y), -sp.diff(psi, x)]


def _case(name, title, header, E, nu, u, reaction, friction):
    """The case dict of tresca_py.mms.derive plus the contact data: ``reaction`` = (p, lt) (sympy), ``friction``
    = ("g_a", expr) or ("coulomb", expr)."""
    kind, law = friction
    measured = f"\nMeasured errors and orders (scikit-fem): reference/h_skfem_{name}.md (make verify regenerates it)."
    return dict(name=name, title=title, header=header + DERIVATION + measured, E=E, nu=nu, corners=UNIT_SQUARE,
                cells=[4, 4], diagonal="first", kinds=KINDS, u=u, g_a=law if kind == "g_a" else None, T=1, steps=8,
                contact=dict(law="unilateral", friction=kind, bound=law, gap=GAP, pressure=reaction[0],
                             lt=reaction[1]),
                expect={"stick_to_slip": True, "slip_to_stick": False, "contact_to_separation": False,
                        "separation_to_contact": True})


HEADER_COMMON = """\
  contact/separation point a(t) = 3/5 + t/5 (contact x < a, separated x > a; points only pass separated -> contact)
  stick/slip point        xi(t) = 1/5 + 2t/5 (slip x < xi; points only pass stick -> slip)
  gap        g(x,t)   = (2 + x)(1 + t)/100,  u.n = -u2(x,0,t) = g - (1/2) max(0, x-a)^3   (u.n <= g, = g in contact)
  pressure   p(x,t)   = max(0, a-x)^2                                            (p >= 0, p (u.n - g) = 0)
  slip       s(x,t)   = u1(x,0,t) = (1/10) max(0, xi-x)^k                        (s' >= 0: slip in +x)
The contact `traction` is sigma(u)n - r with the reaction r = -p n + lt tau, so (p, lt) are the exact contact
pressure and friction traction; f = -div sigma(u), Neumann data sigma(u)n, u0 = u(.,0).
Regularity: u(.,t) is C^2 with piecewise smooth third derivatives (W^{3,inf}), p is C^1 (a smoother pressure
than the physical square root, which would leave u in H^(5/2-eps) only). Predicted: energy/H1 error O(h),
L2 error O(h^2). The fronts move monotonically, so u satisfies every backward-Euler step exactly: no time
error, the errors do not depend on N."""
DERIVATION = """
Derivation and pointwise checks (Signorini and the friction law): tresca_py/mms/signorini*.py."""


def case_signorini_moving():
    """Signorini-Tresca, E = 10, nu = 0.3, contact/separation and stick/slip points both moving."""
    E, nu = R(10), R(3, 10)
    _, mu = lame(E, nu)
    un, p, s = contact_traces()
    ga = G0 * (1 + x / 2)
    lt = -ga + G0 * PosPow(x - XI_OF_T, 3)
    header = ("Signorini-Tresca on Gamma_C = bottom side y = 0 of the unit square (clamped top, Neumann left/right),\n"
              "both transition points moving. E = 10, nu = 0.3.\n" + HEADER_COMMON + """
  friction   g_a(x)   = (1/5)(1 + x/2) on all of Gamma_C,  lt = sigma_t.tau = -g_a + (1/5) max(0, x-xi)^3
  u1 = phi0(y) s - phi1(y) lt/mu + y^2(1-y)(1+t)cos(x)/20,  u2 = -phi0(y) u.n + y(1-y)(1+x)(1+t/2)/20,
  phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2, k = 3.""")
    return _case("mms_signorini_moving", "MMS (issue 40): Signorini-Tresca, moving contact/separation and "
                 "stick/slip points", header, E, nu, general_field(un, s, lt, mu), (p, lt), ("g_a", ga))


def case_signorini_incompressible():
    """Signorini-Tresca with lambda/mu = 1e4 (mu = 1) and a divergence-free u: the data do not depend on lambda."""
    lam_, mu = R(10000), R(1)
    E = mu * (3 * lam_ + 2 * mu) / (lam_ + mu)
    nu = lam_ / (2 * (lam_ + mu))
    un, p, s = contact_traces(slip_power=4)
    ga = G0 * (1 + x / 2)
    lt = -ga + G0 * PosPow(x - XI_OF_T, 3)
    header = ("Near-incompressible Signorini-Tresca: lambda = 1e4, mu = 1 (lambda/mu = 1e4; E = 30002/10001,\n"
              "nu = 5000/10001), u = curl psi divergence-free, so sigma(u) = 2 mu eps(u) and no datum depends\n"
              "on lambda: a locking-free element keeps its errors bounded as lambda grows.\n" + HEADER_COMMON + """
  friction   g_a(x)   = (1/5)(1 + x/2) on all of Gamma_C,  lt = sigma_t.tau = -g_a + (1/5) max(0, x-xi)^3
  u = (psi_y, -psi_x),  psi = phi0(y) Psi0 + phi1(y) s + y^2(1-y)^2 (1+t) sin(x)/20,
  Psi0 = int_0^x g - (1/8) max(0, x-a)^4  (so u.n = d Psi0/dx), phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2,
  k = 4 (u2 holds s_x, f its third derivative).""")
    return _case("mms_signorini_incompressible", "MMS (issue 40): near-incompressible Signorini-Tresca "
                 "(lambda/mu = 1e4), moving fronts", header, E, nu, divfree_field(un, s), (p, lt), ("g_a", ga))


def case_coulomb(stick_margin=None):
    """Signorini-Coulomb: threshold F p with the exact pressure; slip zone x < xi(t) inside the contact zone."""
    E, nu = R(10), R(3, 10)
    stick_margin = R(1, 2) if stick_margin is None else stick_margin
    un, p, s = contact_traces()
    F = (2 + x) / 5
    lt = -F * p * (1 - stick_margin * SStep((x - XI_OF_T) / R(1, 5), 0))
    header = ("Signorini-Coulomb on Gamma_C = bottom side y = 0 of the unit square (clamped top, Neumann\n"
              "left/right), both transition points moving. E = 10, nu = 0.3.\n" + HEADER_COMMON + """
  friction   F(x) = (2 + x)/5 (Coulomb),  lt = sigma_t.tau = -F p (1 - (1/2) S((x - xi)/(1/5))),
             S the C^2 smoothstep: |lt| = F p where slipping (x < xi), |lt| < F p in the stick zone
             xi < x < a, lt = 0 where separated (threshold F p = 0, slip free; s = 0 there).
  u1 = phi0(y) s + y^2(1-y)(1+t)cos(x)/20,  u2 = -phi0(y) u.n + y(1-y)(1+x)(1+t/2)/20, k = 3 (lt is C^1 only,
  so it stays out of u: the surface load carries it).
The threshold is consistent with the exact pressure, so the same orders show that the Coulomb solver
converges to this solution and not merely to some fixed point.""")
    return _case("mms_signorini_coulomb", "MMS (issue 40): Signorini-Coulomb, threshold F p, moving fronts",
                 header, E, nu, general_field(un, s, 0, lame(E, nu)[1]), (p, lt), ("coulomb", F))


SIGNORINI_CASES = [case_signorini_moving, case_signorini_incompressible, case_coulomb]

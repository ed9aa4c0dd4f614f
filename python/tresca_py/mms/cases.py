"""The manufactured cases of verification/cases/mms_*.toml (verification/mms/README.md) and the self-test:
deliberately wrong variants of them that the checks must reject."""
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.mms.blocks import PosPow, SStep
from tresca_py.mms.checks import run_checks
from tresca_py.mms.derive import CheckFailed
from tresca_py.elastic import lame
from tresca_py.mms.elasticity import Xs, local_field, to_global

x, y, t = symbols()
R = sp.Rational

UNIT_SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]


def case_elastic():
    E, nu = R(100), R(3, 10)
    u = [x * (1 + t) * sp.cos(y + x / 2) / 10,
         x * (1 - t / 2) * sp.sin(x * y + R(1, 2)) / 20 + x ** 2 * y / 40]
    return dict(
        name="mms_elastic", title="MMS (d): plain elasticity, smooth exact solution, no contact",
        header="""\
Plain plane-strain elasticity (no contact part), smooth exact solution
    u1 = x (1+t) cos(y + x/2) / 10
    u2 = x (1-t/2) sin(x y + 1/2) / 20 + x^2 y / 40
on the unit square, clamped at x = 0 (left), tractions g = sigma(u) n on bottom/right/top,
body force f = -div sigma(u). E = 100, nu = 0.3, rho = 10.
Each time step is an independent elastic solve (no history), so there is no time error.
Expected: energy / H1 error O(h), L2 error O(h^2) under refinement (refine = 0, 1, 2, ...).
Measured errors and rates: reference/cross_check.md and `tresca-cr study` on this scene.""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "neumann", "right": "neumann", "top": "neumann", "left": "dirichlet"},
        u=u, g_a=None, T=1, steps=2, expect={})


def case_front(slip_sign=1):
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    g0, A, w = R(1, 5), R(1, 20), R(1, 2)
    xi = R(1, 4) + R(1, 2) * t
    ga = g0 * (1 + Xs / 2)
    s = slip_sign * A * SStep((xi - Xs) / w, 0)
    delta = R(1, 4)                                # width over which the stick margin saturates
    lam_t = -ga + R(3, 2) * g0 * (SStep((Xs - xi) / delta, 0) + SStep((xi - w - Xs) / delta, 0))
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_front", title="MMS (a): travelling slip pulse on the bottom side (stick->slip->stick fronts)",
        header="""\
Moving stick-slip fronts on Gamma_C = bottom side y = 0 of the unit square (clamped top y = 1,
Neumann left/right). Exercises: h-convergence with moving fronts in both directions.
Slip zone at time t:  xi(t) - w < x < xi(t),  xi(t) = 1/4 + t/2,  w = 1/2,  T = 1
  (t = 0: 0 < x < 0.25;  t = 1: 0.25 < x < 0.75). Points 0.25 < x < 0.75 pass stick -> slip at the
  leading front; points 0 < x < 0.25 pass slip -> stick at the trailing front.
  slip        s(x,t)  = u1(x,0,t) = (1/20) S((xi(t)-x)/w),  S(c) = 10c^3-15c^4+6c^5 on [0,1], clamped
                        (s' >= 0: slip in +x; s' -> 0 continuously at both fronts)
  friction    g_a(x)  = (1/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) + (3/10)[S((x-xi)/d) + S((xi-w-x)/d)],  d = 1/4
                        (= -g_a in the slip zone; the stick margin rises like 10(z/d)^3 and
                        saturates at 3/10 within d = 1/4 of either front)
  u1 = phi0(y) s + phi1(y) (-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20,
  phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2.  E = 10, nu = 0.3 (mu = 50/13).
u(.,t) is C^2 (in H^3 even), so expected: energy/H1 error O(h), L2 error O(h^2).
Time: s' is continuous and vanishes at both fronts; the exact solution satisfies the backward-Euler
inclusion at the nodes except on the O(k) strip the trailing front crosses in a step, where the
traction defect is O(k^3): the energy error does not depend on N. The L2 error does a little at
coarse N (time/space cancellation) and settles for N >= 64, hence steps = 64 for the h study.
Measured errors and rates: reference/h_mms_front.md (make verify regenerates it).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=64,
        expect={"stick_to_slip": True, "slip_to_stick": True})


def case_stick_to_slip():
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    g0, A = R(1, 5), R(1, 10)
    xi = R(1, 5) + R(3, 5) * t
    ga = g0 * (1 + Xs / 2)
    s = A * PosPow(xi - Xs, 3)
    lam_t = -ga + g0 * PosPow(Xs - xi, 3)
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_stick_to_slip", title="MMS: advancing slip front, points only pass from stick to slip",
        header="""\
Advancing slip front on Gamma_C = bottom side y = 0 of the unit square (clamped top, Neumann left/right).
Slip zone at time t: 0 < x < xi(t), xi(t) = 1/5 + 3t/5 (t = 0: x < 0.2; t = 1: x < 0.8). Points only
ever pass from stick to slip, and slip is monotone (s' >= 0).
  slip        s(x,t) = u1(x,0,t) = (1/10) max(0, xi(t)-x)^3
  friction    g_a(x) = (1/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) + (1/5) max(0, x-xi(t))^3
  u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20,
  phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2.  E = 10, nu = 0.3.
FINDING to show: the exact u satisfies the backward-Euler step EXACTLY at every node (a point whose
slip increment over (t_{n-1}, t_n] is non-zero is slipping at t_n, so sigma_t(t_n) = -g_a there), so
the semi-discretisation in time has zero error: the error is independent of N (only the spatial O(h)
energy / O(h^2) L2 error remains, up to the O(h)-wide discrete front).
Measured errors, independent of N: reference/be_exact_stick_to_slip.md (make verify regenerates it).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=8,
        expect={"stick_to_slip": True, "slip_to_stick": False})


def case_rotated():
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    c, sn = R(4, 5), R(3, 5)                       # rotation by atan(3/4) = 36.87 deg, exact
    g0, A = R(1, 5), R(1, 10)
    xi = R(4, 5) - R(3, 5) * t                     # front moves towards X = 0
    ga = g0 * (1 + Xs / 2)
    s = -A * PosPow(Xs - xi, 3)                    # slip zone X > xi(t), slip in -tau direction
    lam_t = ga - g0 * PosPow(xi - Xs, 3)           # = +g_a in the slip zone
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, X_of = to_global(U1, U2, c, sn)
    corners = [[0, 0], [c, sn], [c - sn, sn + c], [-sn, c]]
    return dict(
        name="mms_rotated", title="MMS (b): contact on a rotated edge (36.87 deg), slip in the -tau direction",
        header="""\
Unit square rotated by theta = atan(3/4) = 36.87 deg (cos = 4/5, sin = 3/5, exact corners), so the
contact edge is not axis-aligned: Gamma_C = side c0->c1 ("bottom") from (0,0) to (0.8,0.6), outward
normal n = (3/5,-4/5), tau = (4/5,3/5). Clamped side "top" (c2->c3), Neumann "left" and "right".
Local coordinates X = (4x+3y)/5 (along Gamma_C), Y = (-3x+4y)/5 (into the body); u = R U(X,Y).
Slip zone at time t: xi(t) < X < 1, xi(t) = 4/5 - 3t/5 (t = 0: X > 0.8; t = 1: X > 0.2); the front
moves towards c0 and points only pass from stick to slip. Slip is in the -tau direction:
  slip        u.tau = U1(X,0,t) = -(1/10) max(0, X-xi(t))^3
  friction    g_a   = (1/5)(1 + X/2)
  traction    sigma_t.tau = +g_a(X) - (1/5) max(0, xi(t)-X)^3   (= +g_a in the slip zone)
  U1 = phi0(Y) s + phi1(Y)(-sigma_t.tau/mu) + Y^2(1-Y)(1+t)cos(X)/20,  U2 = Y(1-Y)(1+X)(1+t/2)/20.
E = 10, nu = 0.3. Expected: energy/H1 O(h), L2 O(h^2); as in mms_stick_to_slip backward Euler is
exact at the nodes (no time error). Exercises the normal/tangent handling on a slanted edge and the
negative slip sign.
Measured errors and rates: reference/h_mms_rotated.md (make verify regenerates it).""",
        E=E, nu=nu, corners=corners, cells=[4, 4], diagonal="second",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, X_of), T=1, steps=8,
        expect={"stick_to_slip": True, "slip_to_stick": False})


def case_stop(stops=True):
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    ts, m = R(1, 3), 30
    g0 = R(2, 5)
    ga = g0 * (1 + Xs / 2)
    a = R(3, 10) * (1 + Xs / 2)                    # slip rate for t < t*
    s = a * (t - PosPow(t - ts, 1)) if stops else a * t   # = a min(t, t*)
    ramp = m * (PosPow(t - ts, 1) - PosPow(t - ts - R(1, m), 1))   # = min(1, m max(0, t-t*))
    lam_t = -ga * (1 - ramp)
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_stop", title="MMS (c): slip stops abruptly at t* = 1/3 (slip velocity jumps)",
        header="""\
Slip that stops abruptly at t* = 1/3 on Gamma_C = bottom side of the unit square (clamped top,
Neumann left/right). Exercises the O(k) time error of backward Euler.
  slip        s(x,t) = u1(x,0,t) = a(x) min(t, t*),  a(x) = (3/10)(1 + x/2)   (s' jumps a -> 0 at t*)
  friction    g_a(x) = (2/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) (1 - min(1, 30 max(0, t-t*)))
              (= -g_a while slipping; leaves the bound linearly after t*, reaches 0 at t* + 1/30)
  u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20.
All of Gamma_C slips (in +x) for t < t* and sticks for t > t*. Data are Lipschitz in time, u is
Lipschitz (not C^1) in time, smooth in space. E = 10, nu = 0.3.
Time behaviour: for t_n < t* backward Euler is exact (constant traction at the bound, constant
slip rate). In the step t_{n-1} < t* < t_n the discrete solution sticks (for N >= 4 the traction
margin g_a min(1, 30 (t_n - t*)) exceeds the stiffness times the missing slip), so it misses the
slip a(x)(t* - t_{n-1}) = a(x) theta k, theta = frac(N t*/T), and keeps that error for all later
times: e(t_n) = theta k ||W|| for t_n > t*, W the elastic field of a unit-rate slip a(x) with zero
loads. Hence O(k), but theta = frac(N/3) alternates 1/3, 2/3 for N = 2^j, so observed rates alternate
~0 and ~2. Use N = 4^j (4, 16, 64, 256: theta = 1/3 always) or N = 2*4^j (theta = 2/3) and compute the
order with log ratio / log 4: E(T) is then the same for N = 4 and 8, 16 and 32, 64 and 128
(theta k = 1/12, 1/48, 1/192). Measured errors and rates: reference/k_study_mms_stop.md and
reference/joint_mms_stop.md (make verify regenerates them).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=4, t_special=[ts],
        expect={"stick_to_slip": False, "slip_to_stick": True})


CASES = [case_front, case_rotated, case_stop, case_elastic, case_stick_to_slip]


def selftest():
    """The checks must catch deliberately wrong data: every mutant below has to FAIL."""
    def scaled_ga(make, factor):
        c = make()
        c["g_a"] = c["g_a"] * factor
        return c

    def shifted(make, du2):
        c = make()
        c["u"] = [c["u"][0], c["u"][1] + du2]
        return c

    mutants = {
        "g_a 1% too small (|sigma_t| > g_a)": lambda: scaled_ga(case_front, R(99, 100)),
        "g_a 1% too large (slip below the bound)": lambda: scaled_ga(case_front, R(101, 100)),
        "slip along sigma_t (wrong direction)": lambda: case_front(slip_sign=-1),
        "slip continues after traction leaves the bound": lambda: case_stop(stops=False),
        "normal displacement on Gamma_C and Gamma_D": lambda: shifted(case_stick_to_slip, t * x / 100),
        "unrotated g_a on the rotated edge": lambda: dict(case_rotated(), g_a=R(1, 5) * (1 + x / 2)),
    }
    for what, make in mutants.items():
        try:
            run_checks(make(), log=lambda msg: None)
        except CheckFailed as err:
            print("   selftest: %-50s caught: %s" % (what, err))
            continue
        raise CheckFailed("selftest: mutant '%s' passed the checks" % what)

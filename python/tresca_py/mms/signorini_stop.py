"""The manufactured Signorini-Tresca case with a genuine backward-Euler error (issue 40, orders in k):
verification/cases/mms_signorini_stop.toml. The normal part is that of tresca_py.mms.signorini (moving
contact/separation point a(t)); the tangential part is mms_stop's (tresca_py.mms.cases.case_stop): all of Gamma_C
slips until t* = 1/3 and then sticks, the slip velocity jumping to zero, so the discrete step that contains t*
misses the slip theta k a(x) and keeps that error: O(k).
"""
from tresca_py.elastic import lame
from tresca_py.mms.blocks import PosPow
from tresca_py.mms.signorini import DERIVATION, R, _case, contact_traces, general_field, t, x

T_STOP = R(1, 3)


def case_signorini_stop(stops=True):
    """Signorini-Tresca whose slip stops abruptly at t* = 1/3 (mms_stop's tangential data), E = 10, nu = 0.3
    (``stops=False``: the slip goes on, a wrong variant for the self-test)."""
    E, nu = R(10), R(3, 10)
    un, p, _ = contact_traces()
    ga = R(2, 5) * (1 + x / 2)
    s = R(3, 10) * (1 + x / 2) * (t - PosPow(t - T_STOP, 1) if stops else t)     # a(x) min(t, t*)
    ramp = 30 * (PosPow(t - T_STOP, 1) - PosPow(t - T_STOP - R(1, 30), 1))     # min(1, 30 max(0, t - t*))
    lt = -ga * (1 - ramp)
    header = """\
Signorini-Tresca with a slip that stops abruptly at t* = 1/3 on Gamma_C = bottom side y = 0 of the unit square
(clamped top, Neumann left/right). E = 10, nu = 0.3. Exercises the O(k) time error of backward Euler.
  contact/separation point a(t) = 3/5 + t/5 (contact x < a, separated x > a; points only pass separated -> contact)
  gap        g(x,t)   = (2 + x)(1 + t)/100,  u.n = -u2(x,0,t) = g - (1/2) max(0, x-a)^3   (u.n <= g, = g in contact)
  pressure   p(x,t)   = max(0, a-x)^2                                            (p >= 0, p (u.n - g) = 0)
  slip       s(x,t)   = u1(x,0,t) = a_s(x) min(t, t*),  a_s = (3/10)(1 + x/2)     (s' jumps a_s -> 0 at t*)
  friction   g_a(x)   = (2/5)(1 + x/2) on all of Gamma_C,
             lt = sigma_t.tau = -g_a (1 - min(1, 30 max(0, t-t*)))   (at the bound while slipping)
  u1 = phi0(y) s - phi1(y) lt/mu + y^2(1-y)(1+t)cos(x)/20,  u2 = -phi0(y) u.n + y(1-y)(1+x)(1+t/2)/20.
The contact `traction` is sigma(u)n - r with the reaction r = -p n + lt tau; f = -div sigma(u), Neumann data
sigma(u)n, u0 = u(.,0). Regularity in space as the other mms_signorini cases (energy O(h), L2 O(h^2)); in time
u is Lipschitz, not C^1: the normal law has no history, the step that contains t* sticks and misses the slip
theta k a_s(x), theta = frac(N t*/T), as in mms_stop: energy error O(k) with a constant proportional to theta
(use N = 4^j, theta = 1/3)."""
    case = _case("mms_signorini_stop", "MMS (issue 40): Signorini-Tresca, slip stops abruptly at t* = 1/3 "
                 "(O(k) time error)", header, E, nu, general_field(un, s, lt, lame(E, nu)[1]), (p, lt), ("g_a", ga))
    case["header"] = header + DERIVATION + ("\nMeasured errors in k (scikit-fem): "
                                            "reference/k_skfem_mms_signorini_stop.md (make verify regenerates it).")
    case["expect"] = dict(case["expect"], stick_to_slip=False, slip_to_stick=True)
    case["steps"], case["t_special"] = 4, [T_STOP]
    return case

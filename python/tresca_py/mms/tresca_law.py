"""The pointwise Tresca check of a manufactured case on its contact sides: u.n equals the prescribed gap,
|sigma_t| <= g_a, stick where |sigma_t| < g_a, slip velocity opposite to sigma_t where slipping, u0
compatible, and the expected stick/slip transitions -- on a fine space-time grid of the parsed expressions.

A static case (``d["static"]``) is one backward-Euler step from u0 = 0: its "velocity" is the increment
u(., T) and only the time T is sampled."""
import numpy as np
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.mms.blocks import lam
from tresca_py.mms.derive import require
from tresca_py.mms.elasticity import side_geometry

x, y, t = symbols()


def np_grad(d, which="parsed"):
    src = d[which]
    return [[lam(src["grad11"]), lam(src["grad12"])], [lam(src["grad21"]), lam(src["grad22"])]]


def stress_np(Gf, lam_, mu, X, Y, T):
    g = [[Gf[i][j](X, Y, T) for j in range(2)] for i in range(2)]
    tr = g[0][0] + g[1][1]
    s11 = lam_ * tr + 2 * mu * g[0][0]
    s22 = lam_ * tr + 2 * mu * g[1][1]
    s12 = mu * (g[0][1] + g[1][0])
    return s11, s12, s22


def side_grid(corners, side, s, times):
    """Points (space, time) of a side of the quadrilateral: X, Y, T arrays, outward normal n, tangent tau."""
    a, b, n, tau = side_geometry(corners, side)
    S_, TT = np.meshgrid(s, times, indexing="ij")
    return a[0] + S_ * (b[0] - a[0]), a[1] + S_ * (b[1] - a[1]), TT, n, tau


def tangential(v1, v2, n):
    """The tangential part (v - (v.n) n) of a vector field and its normal component v.n."""
    vn = v1 * n[0] + v2 * n[1]
    return v1 - vn * n[0], v2 - vn * n[1], vn


def traction_t(d, PX, PY, TT, n):
    """sigma_t = sigma(u) n - (sigma(u) n . n) n from the parsed grad (components)."""
    s11, s12, s22 = stress_np(np_grad(d), float(d["lam"]), float(d["mu"]), PX, PY, TT)
    st1, st2, _ = tangential(s11 * n[0] + s12 * n[1], s12 * n[0] + s22 * n[1], n)
    return st1, st2


def velocity(d, PX, PY, TT):
    """u_t' (sympy derivative of the parsed u; for a static case the increment u(., T) - u0, u0 = 0); for
    a time-dependent case it must agree with the derivative by the building blocks' own rules."""
    P = d["parsed"]
    if d.get("static"):
        return lam(P["u1"])(PX, PY, TT), lam(P["u2"])(PX, PY, TT)
    v = [lam(sp.diff(P[k], t))(PX, PY, TT) for k in ("u1", "u2")]
    w = [lam(sp.diff(d["sym"][k], t))(PX, PY, TT) for k in ("u1", "u2")]
    vnd = max(np.max(np.abs(v[0] - w[0])), np.max(np.abs(v[1] - w[1])))
    require(vnd < 1e-12, "%s: time derivative (Max/Heaviside) != custom rule (%.2e)" % (d["name"], vnd))
    return v[0], v[1]


def check_tresca_law(d, side, s, times, gap=None, log=print):
    """Tresca's law on contact side ``side`` at the samples ``s`` (in [0, 1] along it) x ``times``, with
    u.n = ``gap`` (a function of (x, y, t); None: u.n = 0). Raises CheckFailed on the first violation."""
    name, static = d["name"], bool(d.get("static"))
    PX, PY, TT, n, tau = side_grid(d["corners"], side, s, times)
    u = [lam(d["parsed"]["u1"])(PX, PY, TT), lam(d["parsed"]["u2"])(PX, PY, TT)]
    un = u[0] * n[0] + u[1] * n[1]
    dn = np.max(np.abs(un - (gap(PX, PY, TT) if gap is not None else 0.0)))
    require(dn < 1e-13, "%s: u.n != %s on Gamma_C (%.2e)" % (name, "gap" if gap is not None else 0, dn))
    st1, st2 = traction_t(d, PX, PY, TT, n)
    st_abs = np.hypot(st1, st2)
    ga = lam(d["parsed"]["g_a"])(PX, PY, TT)
    require(np.min(ga) > 0 or static and np.min(ga) >= 0, "%s: g_a must be positive" % name)
    require(np.all(ga == ga[:, :1]), "%s: g_a depends on t" % name)
    vt1, vt2, _ = tangential(*velocity(d, PX, PY, TT), n)
    ttol = 1e-11 * np.max(ga)
    vtol = 1e-11 * max(1e-3, np.max(np.hypot(vt1, vt2)))
    stick, slip = friction_law(name, (st1, st2), (vt1, vt2), ga, ttol, vtol)
    vt_abs = np.hypot(vt1, vt2)
    n_ss, n_sk = (0, 0) if static else check_in_time(d, stick, slip, st_abs - ga, times, ttol)
    st_tau = st1 * tau[0] + st2 * tau[1]
    log("Tresca on %s (%d x %d samples): u.n = gap, |sig_t|<=g_a, stick, slip dir, u0   ok"
        % (side, len(s), len(times)))
    log("   stick %.0f%%, slipping %.0f%% of samples; %d points stick->slip, %d slip->stick; "
        "sigma_t.tau in [%.3g, %.3g], g_a in [%.3g, %.3g], max|slip rate| %.3g, max|u.n| %.3g"
        % (100 * stick.mean(), 100 * slip.mean(), n_ss, n_sk, st_tau.min(), st_tau.max(),
           ga.min(), ga.max(), vt_abs.max(), np.max(np.abs(un))))


def friction_law(name, st, vt, bound, ttol, vtol):
    """The friction law at samples: tangential traction ``st`` = (st1, st2), slip velocity ``vt``, threshold
    ``bound`` (g_a, or F p for Coulomb), tolerances ``ttol`` (traction) and ``vtol`` (velocity):
    |sigma_t| <= bound; |sigma_t| < bound => u_t' = 0; u_t' != 0 => |sigma_t| = bound and u_t' = -theta sigma_t,
    theta >= 0 (where the bound is positive: a zero bound leaves the slip free). Returns the boolean arrays
    (stick, slip); raises CheckFailed on the first violation."""
    st1, st2 = st
    vt1, vt2 = vt
    st_abs, vt_abs = np.hypot(st1, st2), np.hypot(vt1, vt2)
    over = np.max(st_abs - bound)
    require(over <= ttol, "%s: |sigma_t| exceeds the threshold (g_a or F p) by %.2e" % (name, over))
    # stick: |sigma_t| < g_a strictly  =>  u_t' = 0
    stick = st_abs < bound - ttol
    bad = np.max(vt_abs[stick]) if stick.any() else 0.0
    require(bad <= vtol, "%s: stick point with slip velocity %.2e" % (name, bad))
    # slip: u_t' != 0  =>  |sigma_t| = g_a and u_t' = -theta sigma_t, theta >= 0
    slip = vt_abs > vtol
    require(slip.mean() > 0.05, "%s: (almost) no slip samples" % name)
    off = np.max(np.abs(st_abs[slip] - bound[slip]))
    require(off <= ttol, "%s: slipping point with |sigma_t| != the threshold (%.2e)" % (name, off))
    held = slip & (bound > ttol)
    theta = -(vt1 * st1 + vt2 * st2)[held] / st_abs[held] ** 2
    require(np.min(theta) >= 0, "%s: slip velocity not opposite to sigma_t" % name)
    res = np.max(np.hypot(vt1[held] + theta * st1[held], vt2[held] + theta * st2[held]))
    require(res <= vtol, "%s: u_t' not parallel to sigma_t (%.2e)" % (name, res))
    return stick, slip


def check_in_time(d, stick, slip, excess, times, ttol):
    """Compatibility of u0 (t = 0 column), stick samples present, and the expected kinds of transitions;
    returns the numbers of points going stick -> slip and slip -> stick."""
    name = d["name"]
    require(times[0] == 0 and np.max(excess[:, 0]) <= ttol, "%s: u0 incompatible" % name)
    require(stick.mean() > 0.05 or name == "mms_stop", "%s: (almost) no stick samples" % name)
    dsl = np.diff(slip.astype(int), axis=1)
    n_ss = int(np.sum(np.any(dsl == 1, axis=1)))            # points that go stick -> slip
    n_sk = int(np.sum(np.any(dsl == -1, axis=1)))           # points that go slip -> stick
    exp = d["expect"]
    require((n_ss > 0) == exp["stick_to_slip"], "%s: stick->slip transitions: %d" % (name, n_ss))
    require((n_sk > 0) == exp["slip_to_stick"], "%s: slip->stick transitions: %d" % (name, n_sk))
    return n_ss, n_sk

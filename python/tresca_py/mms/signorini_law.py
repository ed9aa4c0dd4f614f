"""The pointwise Signorini check of a manufactured unilateral case on its contact sides, from the printed data
alone (the strings the solvers read): the contact reaction is r = sigma(grad) n - (contact traction), its
pressure p = -r.n and friction traction sigma_t = r - (r.n) n; then

* Signorini: p >= 0, u.n - g <= 0, p (u.n - g) = 0, both contact and separated samples present and the
  expected kinds of transitions of the contact/separation point (and only those);
* the friction law (tresca_py.mms.tresca_law.friction_law) with the threshold g_a (Tresca, on all of
  Gamma_C) or F p (Coulomb: zero where separated, the slip there free), and its stick/slip transitions,

on a fine space-time grid. A violation raises CheckFailed naming the case and the law."""
import numpy as np

from tresca_py.mms.blocks import lam
from tresca_py.mms.derive import require
from tresca_py.mms.tresca_law import friction_law, np_grad, side_grid, stress_np, tangential, velocity


def reaction(d, side, PX, PY, TT, n):
    """(p, st1, st2): the pressure and the tangential reaction of the printed data at the samples."""
    P = d["parsed"]
    s11, s12, s22 = stress_np(np_grad(d), float(d["lam"]), float(d["mu"]), PX, PY, TT)
    r1 = s11 * n[0] + s12 * n[1] - lam(P["ct_%s_1" % side])(PX, PY, TT)
    r2 = s12 * n[0] + s22 * n[1] - lam(P["ct_%s_2" % side])(PX, PY, TT)
    st1, st2, rn = tangential(r1, r2, n)
    return -rn, st1, st2


def signorini_law(name, p, gap_excess, ptol, gtol):
    """Signorini at samples: p >= 0, u.n - g <= 0, p (u.n - g) = 0; returns the boolean array of the samples in
    contact (u.n = g within ``gtol``)."""
    require(np.min(p) >= -ptol, "%s: negative contact pressure %.2e" % (name, np.min(p)))
    require(np.max(gap_excess) <= gtol, "%s: penetration u.n - g = %.2e > 0" % (name, np.max(gap_excess)))
    comp = np.max(np.abs(p * gap_excess))
    require(comp <= ptol * gtol + 1e-14, "%s: complementarity p (u.n - g) = %.2e" % (name, comp))
    touching = gap_excess > -gtol
    require(touching.mean() > 0.05, "%s: (almost) no samples in contact" % name)
    require(touching.mean() < 0.95, "%s: (almost) no separated samples" % name)
    return touching


def transitions(state, times_axis=1):
    """(number of points entering, number of points leaving) the boolean ``state`` along the time axis."""
    ds = np.diff(state.astype(int), axis=times_axis)
    return int(np.sum(np.any(ds == 1, axis=1))), int(np.sum(np.any(ds == -1, axis=1)))


def check_signorini_law(d, side, s, times, log=print):
    """Signorini and the friction law on contact side ``side`` at samples ``s`` (in [0, 1] along it) x
    ``times`` (times[0] = 0: the initial state is checked as well)."""
    name, P = d["name"], d["parsed"]
    PX, PY, TT, n, _ = side_grid(d["corners"], side, s, times)
    un = lam(P["u1"])(PX, PY, TT) * n[0] + lam(P["u2"])(PX, PY, TT) * n[1]
    excess = un - lam(P["gap_%s" % side])(PX, PY, TT)
    p, st1, st2 = reaction(d, side, PX, PY, TT, n)
    pscale = max(1.0, np.max(p))
    touching = signorini_law(name, p, excess, 1e-11 * pscale, 1e-13)
    coulomb = d["contact"]["friction"] == "coulomb"
    bound = lam(P["coulomb"])(PX, PY, TT) * np.maximum(p, 0) if coulomb else lam(P["g_a"])(PX, PY, TT)
    require(np.min(bound) >= 0, "%s: negative friction threshold" % name)
    vt1, vt2, _ = tangential(*velocity(d, PX, PY, TT), n)
    ttol = 1e-11 * max(np.max(bound), pscale)
    vtol = 1e-11 * max(1e-3, np.max(np.hypot(vt1, vt2)))
    stick, slip = friction_law(name, (st1, st2), (vt1, vt2), bound, ttol, vtol)
    got = dict(zip(("separation_to_contact", "contact_to_separation"), transitions(touching), strict=True))
    got.update(zip(("stick_to_slip", "slip_to_stick"), transitions(slip), strict=True))
    for kind, count in got.items():
        require((count > 0) == d["expect"][kind], "%s: %s transitions: %d" % (name, kind, count))
    log("Signorini on %s (%d x %d samples): p >= 0, u.n <= g, p (u.n - g) = 0   ok" % (side, len(s), len(times)))
    log("%s on %s: |sig_t| <= %s, stick, slip dir   ok" % ("Coulomb" if coulomb else "Tresca", side,
                                                        "F p" if coulomb else "g_a"))
    log("   contact %.0f%%, stick %.0f%%, slipping %.0f%% of samples; transitions %s; max p %.3g, min u.n - g %.3g"
        % (100 * touching.mean(), 100 * stick.mean(), 100 * slip.mean(),
           ", ".join("%s %d" % kv for kv in got.items()), np.max(p), np.min(excess)))

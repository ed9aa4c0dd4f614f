"""The stability cases of the domain and the data: thin domains and stretched meshes, loads from 1e-300
to 1e300, a singular set-up, and no NaN/Inf in any results file."""
import os
import re

import h5py
import numpy as np

from tresca_py.common import rel_to as rel
from tresca_py.verify.stability.harness import EX51, MMS_EL, h5, run, sub, write


def case_thin(st):
    base = open(MMS_EL).read()
    out, ok = [], True
    configs = [("square 4×4 (reference)", "[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]", "[4, 4]"),
               ("thin 1:100, square cells", "[[0.0, 0.0], [1.0, 0.0], [1.0, 0.01], [0.0, 0.01]]", "[100, 1]"),
               ("thin 1:100, cells 12.5:1", "[[0.0, 0.0], [1.0, 0.0], [1.0, 0.01], [0.0, 0.01]]", "[8, 1]"),
               ("square, stretched cells 32:1", "[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]", "[2, 64]")]
    for name, corners, cells in configs:
        txt = sub(sub(base, r"^corners\s*=.*$", f"corners = {corners}"), r"^cells\s*=.*$", f"cells = {cells}")
        p = write(st, txt, f"thin_{len(out)}.toml")
        errs = []
        for r in (0, 1, 2):
            res = run(st, p, "--refine", r, out=f"thin_{len(out)}_{r}.h5")
            if res["rc"] != 0 or not res["err"]:
                errs.append(None)
                ok = False
                continue
            errs.append(res["err"])
        rates = [np.log2(errs[i][0] / errs[i + 1][0]) for i in range(2) if errs[i] and errs[i + 1]]
        out.append(f"{name}: energy errors " + ", ".join(f"{e[0]:.3e}" if e else "fail" for e in errs)
                   + f" (orders {', '.join(f'{v:.2f}' for v in rates)})")
        ok &= bool(rates) and rates[-1] >= 0.7
    st.check("thin domain (aspect 1:100) and stretched meshes (mms_elastic data on the new domains, refine 0..2)",
          "runs, finite, energy error converges with order ≈ 1 (≥ 0.7 on the last refinement) on every domain/mesh",
          "; ".join(out), ok)


F32_MAX = float(np.finfo(np.float32).max)  # 3.4e38: above it a VTKHDF/XDMF view would hold inf
F32_TINY = float(np.finfo(np.float32).tiny)  # 1.2e-38: below it a view would show zeros (refused, issue 34)
F64_MAX = float(np.finfo(np.float64).max)  # 1.8e308: the energy a_h(u, u) ~ f² must stay below it
# A run is classified only where f is at least this factor from a limit. The views' limits are sharp: u
# scales exactly to 1e-12 and the stored f32 maxima are rounded to 6e-8, so 1.01 covers them. The energy is
# a sum whose partial sums may exceed the total (cancellation in u·Ku): a factor 10 in f (100 in energy).
VIEW_MARGIN, ENERGY_MARGIN = 1.01, 10.0


def unit_load_limits(path):
    """The quantities of a results file of the unit load (f = 1) that decide whether the run with loads
    × f is representable: the smallest nonzero per-step max |u(m_e)| (`/tresca/u`, what the views'
    underflow check looks at), the largest |value| of the f32 views and the largest energy."""
    with h5py.File(path, "r") as h:
        per_step = np.max(np.abs(h["tresca/u"][()]).reshape(h["tresca/u"].shape[0], -1), axis=1)
        views = []
        h.visititems(lambda _, o: views.append(float(np.max(np.abs(o[()]), initial=0.0)))
                     if isinstance(o, h5py.Dataset) and o.dtype == np.float32 else None)
        energy = max(float(np.max(np.abs(h[k][()]))) for k in ("tresca/energy", "tresca/steps/stored_energy",
                                                                "tresca/steps/external_work"))
    return dict(u_min=float(np.min(per_step[per_step > 0])), views=max(views), energy=energy)


def load_scale_limit(f, lim):
    """Why loads × f (f > 0) cannot be written, by the unit-load limits `lim` of :func:`unit_load_limits`:
    "underflow" (a view's u below f32's normal range), "overflow" (a view above f32's range, or the
    energy, ~ f², above f64's), "border" (within VIEW_MARGIN or ENERGY_MARGIN of a limit: either outcome is
    right), or None (representable: the run must succeed and scale exactly)."""
    lo, hi, e_hi = F32_TINY / lim["u_min"], F32_MAX / lim["views"], np.sqrt(F64_MAX / lim["energy"])
    near = [(lo, VIEW_MARGIN), (hi, VIEW_MARGIN), (e_hi, ENERGY_MARGIN)]
    if any(x / m < f < x * m for x, m in near):
        return "border"
    if f < lo:
        return "underflow"
    if f > min(hi, e_hi):
        return "overflow"
    return None


def case_load(st):
    """Issue 18: loads (traction and g_a together) from 1e-300 to 1e300 on Example 5.1."""
    base = open(EX51).read()
    trac = r'^traction = \["0.02\*\(5-y\)\*t", "-0.01\*t"\]'
    runs, out, ok = {}, [], True
    for f in [1e-300, 1e-200, 1e-100, 1e-10, 1.0, 1e10, 1e30, 1e36, 1e40, 1e100, 1e200, 1e300]:
        txt = sub(base, trac, f'traction = ["{f!r}*0.02*(5-y)*t", "-{f!r}*0.01*t"]')
        txt = sub(txt, r'^g_a\s*=.*$', f'g_a = "{f!r}*0.0012"')
        runs[f] = run(st, write(st, txt, f"load_{f}.toml"), "--refine", 2, out=f"load_{f}.h5")
    u1, lim = h5(runs[1.0]["h5"], "tresca/u"), unit_load_limits(runs[1.0]["h5"])
    worst, refused = 0.0, []
    for f, r in runs.items():
        limit = load_scale_limit(f, lim)
        if r["rc"] == 0:
            d = rel(h5(r["h5"], "tresca/u") / f, u1)
            worst = max(worst, d)
            ok &= d <= 1e-12 and limit in (None, "border")
            out.append(f"{f:g}: rel. diff {d:.1e}" + ("" if limit in (None, "border") else f" (UNEXPECTED: {limit})"))
        else:
            msg = r["stderr"]
            named = {"underflow": "below the single-precision range" in msg,
                     "overflow": "exceeds the single-precision range" in msg or "overflows f64" in msg}
            ok &= limit == "border" and any(named.values()) or named.get(limit, False)
            refused.append(f"{f:g}")
            said = (re.search(r"step \d+: [^;]*", msg) or re.search(".*", msg))[0][:90]
            out.append(f"{f:g}: refused ({limit or 'REPRESENTABLE'}, "
                       f"{'named' if any(named.values()) else 'UNNAMED'}: …{said})")
            if r["h5"] and os.path.exists(r["h5"]):
                with h5py.File(r["h5"], "r") as h:
                    ok &= h["tresca"].attrs["status"] != "completed"
                st.h5_files.remove(r["h5"])
    st.check("loads × f, f from 1e-300 to 1e300 (traction and g_a together; Example 5.1, refine 2, 40 steps)",
          "u_f = f·u_1 to rounding (j_h is positively homogeneous: the step problems scale exactly) wherever the "
          "answer is representable: max|u_f/f − u_1|/max|u_1| ≤ 1e-12; beyond (the f32 VTKHDF/XDMF views' range "
          "1.2e-38..3.4e38, or the energy a_h(u,u) ~ f² above 1.8e308, judged from the f = 1 run's maxima) refused "
          "with a message naming the limit crossed and no 'completed' file",
          f"worst {worst:.1e}; representable for f in [{F32_TINY / lim['u_min']:.1e}, "
          f"{min(F32_MAX / lim['views'], np.sqrt(F64_MAX / lim['energy'])):.1e}]; refused at f = "
          f"{', '.join(refused) or 'none'}; " + "; ".join(out), ok)


def case_singular(st):
    base = open(MMS_EL).read()
    txt = sub(base, r'^name = "left"\nkind = "dirichlet"', 'name = "left"\nkind = "neumann"')
    r = run(st, write(st, txt, "nodirichlet.toml"))
    st.check("singular set-up: no Dirichlet part (rigid motions free)",
          "refused with a message naming the cause, non-zero exit, no results file written",
          f"rc {r['rc']}, stderr '{r['stderr'][:200]}'",
          r["rc"] != 0 and ("positive definite" in r["stderr"] or "rigid motions" in r["stderr"]))


def case_finite(st):
    bad = []
    n = 0
    for p in st.h5_files:
        if not p or not os.path.exists(p):
            continue
        with h5py.File(p, "r") as f:
            def visit(name, obj, p=p):
                nonlocal n
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f":
                    n += 1
                    if not np.all(np.isfinite(obj[()])):
                        bad.append(f"{os.path.basename(p)}:{name}")
            f.visititems(visit)
    st.check("no NaN or Inf in any results file written by the cases above",
          "every floating-point dataset of every results file finite",
          f"{len(st.h5_files)} files, {n} datasets checked; non-finite: {bad[:10] or 'none'}", not bad)

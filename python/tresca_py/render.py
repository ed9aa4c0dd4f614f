"""Pictures of a tresca-cr results file (reads only the ``tresca`` group, matplotlib Agg).

    .venv/bin/python scripts/render.py run.h5 [--times 0.25 0.5 1.0] [-o DIR] [--field vm|u] [--scale S]

For each chosen time (nearest stored step; default: quarter, half and final time) writes
* ``DIR/deformed_<n>.png``: the deformed body (CR field as discontinuous P1 on each triangle, displacement
  magnified by S, stated in the title; default: 10 % of the body's size over max |u|), coloured by von Mises
  stress or |u|, with Γ_C drawn in black;
* ``DIR/contact_<n>.png`` (when Γ_C exists): σ_τ/ḡ along Γ_C and the slip velocity Δs/Δt, with slip
  edges shaded;
* ``DIR/normal_<n>.png`` (unilateral or Coulomb runs, whose files hold the normal condition): the contact
  pressure p along Γ_C, and |σ_τ| over the friction threshold (ḡ_e on a Tresca edge, F̄_e p_e on a Coulomb
  one), 1 on a slipping edge and below 1 on a sticking one; stick, slip and separated edges shaded apart.
Only committed steps are drawn: a killed or stopped run is said so on stdout and in every title. Axis and
colour-bar units come from the scene's optional ``[units]`` table (``length``, ``force``, ``time``; stress is
force/length²), read from the scene text stored in the file; without it the labels say "length",
"force/length²", "time". Bad input (an unreadable or invalid results file, a non-finite or negative
``--scale`` or ``--times``, an output directory that cannot be written) gives one ``error:`` line and exit 2,
before anything is drawn.
"""
import argparse
import math
import os
import sys
import textwrap
import tomllib

import numpy as np
from matplotlib.collections import LineCollection, PolyCollection
from matplotlib.figure import Figure

from . import audit, fields, paths, results


def units(scene_text):
    """Unit labels from the scene's optional [units] table."""
    try:
        u = tomllib.loads(scene_text).get("units", {})
    except (tomllib.TOMLDecodeError, TypeError):
        u = {}
    L, F, T = u.get("length", "length"), u.get("force", "force"), u.get("time", "time")
    return {"L": L, "S": f"{F}/{L}²", "T": f" {u['time']}" if "time" in u else "", "V": f"{L}/{T}"}


def load(path):
    """The committed steps of a results file (validated, ``tresca_py.results``) as the dict the pictures use."""
    r = results.read(path)
    d = {"mesh/points": r.mesh.points, "mesh/triangles": r.mesh.triangles, "mesh/edges": r.mesh.edges,
         "te": r.mesh.triangle_edges(), "times": r.times, "u": r.u, "E": float(r.attrs["E"]),
         "nu": float(r.attrs["nu"]), "title": str(r.attrs.get("title", "")) or os.path.basename(path),
         "units": units(str(r.attrs.get("scene", ""))), "note": r.note}
    if r.contact is not None:
        for k in ("edges", "tangent", "g", "slip", "sigma_t", "state", "pressure", "status", "coulomb"):
            if getattr(r.contact, k) is not None:
                d["c_" + k] = getattr(r.contact, k)
    d["audit"] = audit.read(path, r.completed)
    return d


def title(d, text):
    """Figure title: the run, what is shown, and the kill/stop note; wrapped, never clipped (bbox tight)."""
    head = d["title"] + (f"  [{d['note']}]" if d["note"] else "")
    return "\n".join(textwrap.wrap(head, 80) + textwrap.wrap(text, 80))


def step_fields(d, n):
    """(triangle vertices (T, 3, 2), vertex displacements (T, 3, 2), von Mises (T,)) at step n."""
    disp = fields.vertex_values(d["u"][n:n + 1], d["te"])
    gl = fields.basis_gradients(d["mesh/points"], d["mesh/triangles"])
    vm = fields.stress(disp, gl, d["E"], d["nu"])[4]
    return d["mesh/points"][d["mesh/triangles"]], disp[0], vm[0]


def deformed(d, n, field, scale, out):
    te = d["te"]
    x, disp, vm = step_fields(d, n)
    size = float(np.ptp(d["mesh/points"], axis=0).max())
    umax = float(np.abs(d["u"]).max()) or 1.0
    s = scale if scale else 0.1 * size / umax
    y = x + s * disp
    u_ = d["units"]
    if field == "vm":
        val, label = vm, f"von Mises stress (plane strain) [{u_['S']}]"
    else:
        val, label = np.linalg.norm(disp, axis=2).mean(axis=1), f"|u| (triangle mean) [{u_['L']}]"
    fig = Figure(figsize=(7.0, 6.0))
    ax = fig.subplots()
    ax.add_collection(PolyCollection(x, facecolors="none", edgecolors="0.8", linewidths=0.4))
    pc = PolyCollection(y, array=val, cmap="viridis", edgecolors="face", linewidths=0.2)
    ax.add_collection(pc)
    fig.colorbar(pc, ax=ax, label=label, shrink=0.85)
    if "c_edges" in d:
        pts = d["mesh/points"]
        e2 = d["mesh/edges"][d["c_edges"]]
        # deformed Γ_C from the trace of the triangle owning each edge
        segs = []
        tri = d["mesh/triangles"]
        for e, (a, b) in zip(d["c_edges"], e2, strict=True):
            t = np.nonzero((te == e).any(axis=1))[0][0]
            ja, jb = list(tri[t]).index(a), list(tri[t]).index(b)
            segs.append([y[t, ja], y[t, jb]])
        ax.add_collection(LineCollection(segs, colors="k", linewidths=2.0, label="Γ_C (deformed)"))
        ax.add_collection(LineCollection(pts[e2], colors="r", linewidths=1.0, linestyles=":", label="Γ_C (reference)"))
        # below the axes, never over the body
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2, fontsize=8, frameon=False)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [{u_['L']}]")
    ax.set_ylabel(f"y [{u_['L']}]")
    ax.set_title(title(d, f"t = {d['times'][n]:.4g}{u_['T']}, step {n}: deformed ×{s:.3g} (grey: reference). "
                    "Gaps between triangles: the CR field is continuous only at edge midpoints"), fontsize=9)
    paths.save_figure(fig, out, dpi=120, bbox_inches="tight")


def contact(d, n, out):
    s, half, order = along(d)
    g = d["c_g"]
    sig = d["c_sigma_t"][n] / np.where(g > 0, g, 1.0)
    times = d["times"]
    if n > 0:
        vel = (d["c_slip"][n] - d["c_slip"][n - 1]) / (times[n] - times[n - 1])
    else:
        vel = np.zeros_like(sig)
    state = d["c_state"][n]
    fig = Figure(figsize=(7, 5.6))
    a1, a2 = fig.subplots(2, 1, sharex=True)
    for ax in (a1, a2):
        for k in np.nonzero(state == 1)[0]:
            ax.axvspan(s[k] - half[k], s[k] + half[k], color="tab:orange", alpha=0.25, lw=0)
        ax.grid(alpha=0.3)
    a1.step(s[order], sig[order], where="mid", color="tab:blue")
    a1.plot(s[order], sig[order], ".", color="tab:blue")
    a1.axhline(1, color="k", lw=0.8, ls="--")
    a1.axhline(-1, color="k", lw=0.8, ls="--")
    u_ = d["units"]
    a1.set_ylabel("σ_τ / ḡ  [–]")
    a1.set_ylim(-1.15, 1.15)
    a2.step(s[order], vel[order], where="mid", color="tab:red")
    a2.plot(s[order], vel[order], ".", color="tab:red")
    a2.set_ylabel(f"slip velocity Δs/Δt [{u_['V']}]")
    a2.set_xlabel(f"position along Γ_C, x·τ [{u_['L']}]")
    nslip = int(state.sum())
    a1.set_title(title(d, f"Γ_C at t = {times[n]:.4g}{u_['T']} (step {n}); "
                          f"shaded: slip ({nslip} of {len(state)} edges)"),
                 fontsize=9)
    paths.save_figure(fig, out, dpi=120, bbox_inches="tight")


def along(d):
    """(position of each Γ_C edge's midpoint along Γ_C, half its extent there, the order along Γ_C)."""
    pts, e2 = d["mesh/points"], d["mesh/edges"][d["c_edges"]]
    tau = d["c_tangent"][0]
    s = pts[e2].mean(axis=1) @ tau  # arclength-like coordinate along Γ_C (straight contact boundary)
    return s, 0.5 * np.abs((pts[e2[:, 1]] - pts[e2[:, 0]]) @ tau), np.argsort(s)


STATUS = ((0, "stick", "tab:blue"), (1, "slip", "tab:orange"), (2, "separated", "tab:gray"))


def threshold_ratio(d, n):
    """|σ_τ| over the friction threshold per Γ_C edge at step n: ḡ_e (Tresca) or F̄_e p_e (Coulomb); NaN on a
    separated edge (no threshold, no traction)."""
    p, status = d["c_pressure"][n], d["c_status"][n]
    cou = d.get("c_coulomb")
    thr = d["c_g"] if cou is None else np.where(np.isnan(cou), d["c_g"], np.nan_to_num(cou) * np.abs(p))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.abs(d["c_sigma_t"][n]) / thr
    return np.where(status == 2, np.nan, ratio)


def normal(d, n, out):
    """The normal condition along Γ_C at step n: pressure, and σ_τ over the threshold (``threshold_ratio``)."""
    s, half, order = along(d)
    status, u_ = d["c_status"][n], d["units"]
    fig = Figure(figsize=(7, 5.6))
    a1, a2 = fig.subplots(2, 1, sharex=True)
    for ax in (a1, a2):
        for code, name, colour in STATUS:
            for i, k in enumerate(np.nonzero(status == code)[0]):
                ax.axvspan(s[k] - half[k], s[k] + half[k], color=colour, alpha=0.2, lw=0,
                           label=name if (i == 0 and ax is a1) else None)
        ax.grid(alpha=0.3)
    p = d["c_pressure"][n]
    a1.step(s[order], p[order], where="mid", color="k")
    a1.plot(s[order], p[order], ".", color="k")
    a1.set_ylabel(f"contact pressure p [{u_['S']}]")
    a1.legend(fontsize=8, loc="best")
    r = threshold_ratio(d, n)
    a2.step(s[order], r[order], where="mid", color="tab:red")
    a2.plot(s[order], r[order], ".", color="tab:red")
    a2.axhline(1, color="k", lw=0.8, ls="--")
    a2.set_ylabel("|σ_τ| / threshold  [–]")
    a2.set_ylim(0, 1.15)
    a2.set_xlabel(f"position along Γ_C, x·τ [{u_['L']}]")
    counts = ", ".join(f"{int(np.sum(status == c))} {name}" for c, name, _ in STATUS)
    a1.set_title(title(d, f"Γ_C at t = {d['times'][n]:.4g}{u_['T']} (step {n}): {counts}; threshold ḡ (Tresca) "
                          "or F̄ p (Coulomb), none where separated"), fontsize=9)
    paths.save_figure(fig, out, dpi=120, bbox_inches="tight")


def energy(d, out):
    """The energy budget over time (``tresca_py.audit``): stored energy, cumulative external and boundary work,
    cumulative frictional and backward-Euler dissipation, and the balance residual on a second axis."""
    paths.save_figure(energy_figure(d), out, dpi=120, bbox_inches="tight")


def energy_figure(d):
    """The figure of ``energy``. Residuals that are exactly zero have no place on the log axis: they are marked
    on its bottom edge and named in the legend, so the axis spans the nonzero residuals only."""
    a, t = d["audit"], d["times"]
    fig = Figure(figsize=(7, 5.6))
    a1, a2 = fig.subplots(2, 1, sharex=True)
    a1.plot(t, a["stored_energy"], label="stored ½a_h(uⁿ,uⁿ)")
    a1.plot(t, np.cumsum(a["external_work"]), label="Σ external work (lⁿ,δuⁿ)")
    if np.any(a["boundary_work"]):
        a1.plot(t, np.cumsum(a["boundary_work"]), label="Σ work on imposed data")
    a1.plot(t, np.cumsum(a["friction_dissipation"]), label="Σ friction j_h(δuⁿ)")
    a1.plot(t, np.cumsum(a["euler_dissipation"]), label="Σ backward Euler ½a_h(δuⁿ,δuⁿ)")
    a1.set_ylabel("energy [force·length]")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    r, tn = np.abs(a["balance_residual"][1:]), t[1:]
    zero = r == 0
    if np.any(~zero):
        a2.semilogy(tn[~zero], r[~zero], ".", color="tab:red", label="|balance residual|")
    if np.any(zero):
        a2.plot(tn[zero], np.zeros(int(zero.sum())), "x", color="tab:gray", transform=a2.get_xaxis_transform(),
                clip_on=False, label=f"exactly 0 ({int(zero.sum())} steps)")
        a2.legend(fontsize=8)
    a2.set_ylabel("|balance residual|")
    a2.set_xlabel(f"time [{d['units']['T'].strip() or 'time'}]")
    a2.grid(alpha=0.3)
    a1.set_title(title(d, "energy budget: a_h(uⁿ,δuⁿ) + j_h(δuⁿ) = (lⁿ,δuⁿ) + W_Γⁿ per step"), fontsize=9)
    return fig


def positive_or_auto(text):
    """--scale: a finite number ≥ 0 (0: automatic)."""
    v = float(text)
    if not math.isfinite(v) or v < 0:
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0 (0: automatic), not {text}")
    return v


def finite(text):
    v = float(text)
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"must be a finite number, not {text}")
    return v


def main(argv=None):
    ap = argparse.ArgumentParser(description="render a tresca-cr results file")
    ap.add_argument("h5")
    ap.add_argument("--times", type=finite, nargs="*", help="times to draw (nearest stored step)")
    ap.add_argument("-o", "--out", default=".", help="output directory")
    ap.add_argument("--field", choices=["vm", "u"], default="vm", help="colour: von Mises or |u|")
    ap.add_argument("--scale", type=positive_or_auto, default=0.0,
                    help="displacement magnification (default 0: automatic)")
    ap.add_argument("--force", action="store_true", help="replace existing pictures")
    args = ap.parse_args(argv)
    try:
        d = load(args.h5)
        out = paths.output_dir(args.out)
        pictures = planned(d, args.times, out)
        # the rule of every output, for all pictures before the first is drawn (tresca_py.paths)
        paths.distinct([(p, "picture") for _, _, p in pictures], [(args.h5, "results file")])
        for _, _, p in pictures:
            paths.new_output(p, "picture", args.force)
    except (results.ResultsError, paths.PathError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    t = d["times"]
    if d["note"]:
        print(f"note: {args.h5}: {d['note']}; drawing committed steps only (t ≤ {t[-1]:.4g})")
    draw = {"deformed": lambda n, p: deformed(d, n, args.field, args.scale, p),
            "contact": lambda n, p: contact(d, n, p), "normal": lambda n, p: normal(d, n, p),
            "energy": lambda n, p: energy(d, p)}
    for kind, n, p in pictures:
        draw[kind](n, p)
        print(p)
    return 0


def planned(d, times, out):
    """The pictures to draw, (kind, step, path): the deformed body (and Γ_C) at the steps nearest ``times`` (default
    a quarter, half and all of the run), and the energy budget when the file has its audit."""
    t = d["times"]
    want = times if times else [t[0] + q * (t[-1] - t[0]) for q in (0.25, 0.5, 1.0)]
    pictures = []
    for n in dict.fromkeys(int(np.argmin(np.abs(t - w))) for w in want):
        pictures.append(("deformed", n, os.path.join(out, f"deformed_{n:06d}.png")))
        if "c_edges" in d:
            pictures.append(("contact", n, os.path.join(out, f"contact_{n:06d}.png")))
        if "c_pressure" in d:
            pictures.append(("normal", n, os.path.join(out, f"normal_{n:06d}.png")))
    if d["audit"] is not None and len(t) > 1:
        pictures.append(("energy", len(t) - 1, os.path.join(out, "energy.png")))
    return pictures

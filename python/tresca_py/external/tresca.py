"""tresca-cr's column: ``tresca-cr run`` per level, its results file read into the compared quantities, and
``tresca-cr study --csv`` for its own estimates.

The CR field is evaluated from the results file: on a triangle with vertices v₀ v₁ v₂ and edge-midpoint values
U_i on the edge opposite vᵢ, u(x) = Σᵢ U_i (1 − 2λᵢ(x)) (λ the barycentric coordinates); ‖u‖²_L2 is exact by the
midpoint rule (|T|/3 Σ|U_i|²), ∇u = −2 Σᵢ U_i ⊗ ∇λᵢ (broken H1). Along Γ_C the trace is taken in the triangle
owning the contact edge (no trace on a curved Γ_C: NaN). ½a_h(u,u) = ½ ``tresca/energy`` (with the jump term);
∫σ_τ = Σ_e σ_τ,e |e|; the stick flag of a contact edge (its midpoint) is its last-step state 0, its stick
margin (``quantities.stick_ends``) φ_e = g_e − |σ_τ,e − p_e δu_τ,e| with the last step's slip increment
δu_τ,e and p_e = γ_N (λ + 2μ)/|e|; on a unilateral scene ∫p = Σ_e p_e|e| and
∫p x² = Σ_e p_e |e| (x₀² + x₀x₁ + x₁²)/3 (p_e constant on the edge).
"""
from __future__ import annotations

import subprocess
import time
from pathlib import Path

import h5py
import numpy as np


def _tri_edges(tri, edges):
    """(T, 3) edge index opposite each vertex."""
    look = {tuple(sorted(e)): k for k, e in enumerate(edges.tolist())}
    return np.array([[look[tuple(sorted((t[1], t[2])))], look[tuple(sorted((t[2], t[0])))],
                      look[tuple(sorted((t[0], t[1])))]] for t in tri.tolist()])


def _bary_grads(P):
    """∇λᵢ (T, 3, 2) and areas (T,) of triangles with vertex coordinates P (T, 3, 2)."""
    d1, d2 = P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    g1 = np.stack([d2[:, 1], -d2[:, 0]], 1) / det[:, None]
    g2 = np.stack([-d1[:, 1], d1[:, 0]], 1) / det[:, None]
    return np.stack([-g1 - g2, g1, g2], 1), 0.5 * np.abs(det)


def read_results(path, probes, pen_scale, contact_mids=None):
    """The raw result dict (``quantities.summarise`` format) at the last time of a results file; with
    ``contact_mids`` (the contact part's edge midpoints) only the contact edges there: tresca-cr writes a
    symmetry part's edges among its contact edges (a symmetry part is a frictionless bilateral contact part)."""
    with h5py.File(path, "r") as f:
        g = f["tresca"]
        pts, tri, edges = g["mesh/points"][:], g["mesh/triangles"][:], g["mesh/edges"][:]
        U = g["u"][-1]
        cedges = g["contact/edges"][:]
        sig, state = g["contact/sigma_t"][-1], g["contact/state"][-1]
        slip = g["contact/slip"][-2:]
        g_mean = g["contact/g"][:]
        energy = 0.5 * float(g["energy"][-1])
        err = {k: float(g[f"errors/{k}"][-1]) for k in ("h1", "l2")} if "errors" in g else {}
        pressure = g["contact/pressure"][-1] if "contact/pressure" in g else None
    if contact_mids is not None:
        keep = _on_part(pts[edges[cedges]].mean(axis=1), np.asarray(contact_mids, dtype=float))
        cedges, sig, state, slip, g_mean = cedges[keep], sig[keep], state[keep], slip[:, keep], g_mean[keep]
        pressure = None if pressure is None else pressure[keep]
    te = _tri_edges(tri, edges)
    P = pts[tri]
    grads, area = _bary_grads(P)
    Ut = U[te]                                    # (T, 3, 2): value on the edge opposite vertex i
    G = -2.0 * np.einsum("tic,tij->tcj", Ut, grads)   # ∇u (T, 2, 2)
    l2 = np.sum(area / 3.0 * np.sum(Ut ** 2, axis=(1, 2)))
    semi = np.sum(area * np.sum(G ** 2, axis=(1, 2)))
    owner = {}
    for t, row in enumerate(te.tolist()):
        for e in row:
            owner.setdefault(e, t)
    start, tau = np.asarray(probes["start"]), np.asarray(probes["tangent"])
    ends = pts[edges[cedges]]                     # (C, 2, 2)
    s_end = np.sort((ends - start) @ tau, axis=1)
    lengths = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)

    def trace(points):
        if probes.get("curved"):  # u·τ along the chord of a curved Γ_C means nothing (problem.contact_probes)
            return np.full(len(points), np.nan)
        points = np.asarray(points)
        s = (points - start) @ tau
        out = np.zeros(len(points))
        for i, (x, si) in enumerate(zip(points, s, strict=True)):
            hits = np.nonzero((s_end[:, 0] <= si + 1e-12) & (si <= s_end[:, 1] + 1e-12))[0]
            vals = []
            for c in hits:
                t = owner[int(cedges[c])]
                lam = np.linalg.solve(np.vstack([P[t].T, np.ones(3)]), np.array([x[0], x[1], 1.0]))
                vals.append(np.sum((1.0 - 2.0 * lam)[:, None] * Ut[t], axis=0) @ tau)
            out[i] = np.mean(vals)  # the mean of both sides at a vertex between two contact edges
        return out
    mids = np.mean(s_end, axis=1)
    raw = {"h1_norm": float(np.sqrt(l2 + semi)), "energy": energy,
           "sigma_t_integral": float(np.sum(sig * lengths)),
           "u_tau_points": trace(probes["points"]).tolist(), "u_tau_samples": trace(probes["samples"]).tolist(),
           "quad_s": mids.tolist(), "quad_stick": (state == 0).astype(int).tolist(), "dofs": int(2 * len(edges)),
           "quad_margin": (g_mean - np.abs(sig - pen_scale / lengths * (slip[-1] - slip[0]))).tolist(),
           "quad_dslip": np.abs(slip[-1] - slip[0]).tolist()}
    if pressure is not None:  # a unilateral scene: p_e = P_e/|e| per contact edge
        raw["normal_force"], raw["max_pressure"] = float(np.sum(pressure * lengths)), float(np.max(pressure))
        x0, x1 = ends[:, 0, 0], ends[:, 1, 0]  # ∫_e x² ds of the edge-constant pressure, exactly
        raw["pressure_x2"] = float(np.sum(pressure * lengths * (x0 * x0 + x0 * x1 + x1 * x1) / 3.0))
    if err:
        raw["err_h1_semi"], raw["err_l2"] = err["h1"], err["l2"]
    return raw


def _on_part(mids, part_mids):
    """Which of the points ``mids`` are (to rounding) among ``part_mids``."""
    from scipy.spatial import cKDTree
    scale = float(np.max(np.ptp(part_mids, axis=0))) or 1.0
    dist, _ = cKDTree(part_mids).query(mids)
    return dist <= 1e-9 * scale


def run_level(binary, scene, refine, steps, out_dir, probes, pen_scale, contact_mids=None, stem=None):
    """``tresca-cr run`` at one level (results file ``STEM.h5``, default ``tresca_rREFINE``); the raw result
    (``read_results``) with its wall time (the run's own ``wall_time`` sum)."""
    out = Path(out_dir) / f"{stem or f'tresca_r{refine}'}.h5"
    cmd = [str(binary), "run", str(scene), "--refine", str(refine), "--steps", str(steps), "-o", str(out),
           "--force", "-q"]
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()[-400:]}")
    raw = read_results(out, probes, pen_scale, contact_mids)
    raw.update({"wall_s": wall, "code": "tresca-cr (CR)", "cmd": cmd})
    return raw


def study_csv(binary, scene, levels, steps, csv_path):
    """``tresca-cr study … --csv`` over the same levels (its own Richardson estimates, kept as a reference file)."""
    lv = ",".join(f"{r}:{steps}" for r in levels)
    cmd = [str(binary), "study", str(scene), "--levels", lv, "--csv", str(csv_path), "--force"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({proc.returncode}): {proc.stderr.strip()[-400:]}")
    return cmd

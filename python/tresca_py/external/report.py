"""Analysis of the external suite's rows: limits and bands per code and quantity, orders of the true errors,
the cost of 1e-4 relative H1 accuracy, the CSV, the markdown table and the log-log plots."""
from __future__ import annotations

import csv
import math
from pathlib import Path

from tresca_py.common import orders

from .quantities import ERRORS, HALF_WIDTH, QUANTITIES, UNILATERAL
from .richardson import limit
from .suite import ORDER, SCENES

ENTRY = "verification/external/run.py"


def by_code(rows, scene):
    out = {}
    for r in rows:
        if r["scene"] == scene:
            out.setdefault(r["code"], []).append(r)
    for v in out.values():
        v.sort(key=lambda r: r["refine"])
    return out


def theory_order(code, scene, q):
    """The theoretical order of quantity q for a code: its H1 order k (capped by the scene's ``order_cap``),
    except the stick–slip endpoints on a scene whose slip grows like the cube of the distance to the fronts
    (``Scene.cubic_front``): the threshold η_h ∝ h² (and a slip error O(h²) or smaller) moves the threshold's
    crossing by O(h^{2/3}) (``quantities``), so the endpoints converge at order 2/3 there."""
    sc = next((s for s in SCENES if s.name == scene), None)
    k = min(ORDER[code], sc.order_cap) if sc is not None else ORDER[code]
    if q == "max_pressure":  # a trace of the stress: ‖σ − σ_h‖ on Γ_C ≲ h^{-1/2} ‖σ − σ_h‖_{L2(Ω)} = O(h^{k−½})
        return k - 0.5
    return 2 / 3 if sc is not None and sc.cubic_front and q in ("stick_a", "stick_b") else k


def limits(rows, scene):
    """{code: {quantity: Limit}} from each code's finest levels (three, and a fourth for the check), for the
    scene's compared quantities (``Scene.quantities``)."""
    sc = next((s for s in SCENES if s.name == scene), None)
    compared = sc.quantities if sc is not None else QUANTITIES
    res = {}
    for code, rs in by_code(rows, scene).items():
        h = [r["h"] for r in rs]
        res[code] = {q: limit(h, [r[q] for r in rs], p_th=theory_order(code, scene, q)) for q in compared}
    return res


def error_orders(rows, scene, key="err_h1_semi", fit_levels=4):
    """{code: (successive orders over all levels, order fitted to the finest ``fit_levels``)} of a true error."""
    out = {}
    for code, rs in by_code(rows, scene).items():
        if all(key in r and r[key] > 0 for r in rs) and len(rs) >= fit_levels:
            succ, _ = orders([r["h"] for r in rs], [r[key] for r in rs])
            _, fit = orders([r["h"] for r in rs[-fit_levels:]], [r[key] for r in rs[-fit_levels:]])
            out[code] = (succ, fit)
    return out


def common_limit(lims, q="h1_norm"):
    """The limit with the narrowest finite band among the codes (the reference for the plots)."""
    cands = [(v[q].gci, v[q].value) for v in lims.values() if math.isfinite(v[q].gci)]
    return min(cands)[1] if cands else math.nan


def write_csv(rows, path):
    keys = ["scene", "code", "refine", "steps", "h", "dofs", "wall_s", "process_s", *QUANTITIES, HALF_WIDTH, *ERRORS]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})


def cost_at(rs, target, key="rel"):
    """(DOF, wall) at which a code's relative error reaches ``target``: measured (first level that meets it)
    or extrapolated along the last two levels' log-log lines (marked "≈")."""
    for r in rs:
        if r[key] <= target:
            return r["dofs"], r["wall_s"], "measured"
    a, b = rs[-2], rs[-1]
    if not (b[key] < a[key]):
        return math.nan, math.nan, "not decreasing"
    s_dof = math.log(b["dofs"] / a["dofs"]) / math.log(a[key] / b[key])
    s_wall = math.log(b["wall_s"] / a["wall_s"]) / math.log(a[key] / b[key])
    f = math.log(b[key] / target)
    return b["dofs"] * math.exp(s_dof * f), b["wall_s"] * math.exp(max(s_wall, 0.0) * f), "extrapolated"


def plots(rows, scenes, lims, out_dir):
    """reference/external_dof.png and external_wall.png: |‖u_h‖_H1 − L|/L against DOF and wall time."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    paths = []
    for xkey, label, fname in (("dofs", "DOF", "external_dof.png"), ("wall_s", "wall time [s]", "external_wall.png")):
        fig, axes = plt.subplots(1, len(scenes), figsize=(4 * len(scenes), 3.6), squeeze=False)
        for ax, sc in zip(axes[0], scenes, strict=True):
            L = common_limit(lims[sc.name])
            for code, rs in by_code(rows, sc.name).items():
                d = [abs(r["h1_norm"] - L) / abs(L) for r in rs]
                pts = [(r[xkey], v) for r, v in zip(rs, d, strict=True) if v > 0]
                if pts:
                    ax.loglog(*zip(*pts, strict=True), "o-", label=code, ms=4)
            ax.set_title(sc.name)
            ax.set_xlabel(label)
            ax.grid(True, which="both", alpha=0.3)
        axes[0][0].set_ylabel("|‖u_h‖_H1 − L| / L")
        axes[0][0].legend(fontsize=7)
        fig.tight_layout()
        p = Path(out_dir) / fname
        fig.savefig(p, dpi=110)
        plt.close(fig)
        paths.append(p)
    return paths


STUDY_OUTPUTS = ("elastic_energy", "max_slip", "stick_length")  # `tresca-cr study`'s output columns


def study_estimates(path):
    """tresca-cr study's own limits (last row of its --csv): {output: text}, the text "limit ± GCI (verdict)"
    or, where the study did not extrapolate (its limit cell is empty), "not extrapolated: why"."""
    if not Path(path).exists():
        return {}
    with open(path) as fh:
        last = list(csv.DictReader(fh))[-1]
    out = {}
    for q in STUDY_OUTPUTS:
        if f"{q}_limit" not in last:
            out[q] = "not in the study's CSV"
            continue
        lim, gci, verdict = last[f"{q}_limit"], last.get(f"{q}_gci", ""), last.get(f"{q}_verdict", "")
        if lim and gci:
            out[q] = f"{float(lim):.6g} ± {float(gci):.2g} ({verdict})"
        else:
            why = verdict.removeprefix("not yet: refine further (").removesuffix(")") if verdict else "no verdict"
            out[q] = f"not extrapolated: {why}"
    return out


def write_all(rows, scenes, notes, reqs, elapsed, ref_dir, out_dir=None):
    """reference/external.csv, external.md, the two plots and tresca-cr's study CSVs."""
    ref_dir.mkdir(parents=True, exist_ok=True)
    write_csv(rows, ref_dir / "external.csv")
    if out_dir is not None:
        for sc in scenes:
            src = Path(out_dir) / sc.name / "tresca_study.csv"
            if src.exists():
                (ref_dir / f"external_study_{sc.name}.csv").write_text(src.read_text())
    lims = {sc.name: limits(rows, sc.name) for sc in scenes}
    plots(rows, scenes, lims, ref_dir)
    (ref_dir / "external.md").write_text(markdown(rows, scenes, notes, reqs, elapsed, lims, ref_dir))


def _fmt(lim):
    if not math.isfinite(lim.value):
        return "—"
    p = f", p={lim.p:.2f}" if lim.extrapolated else (", not extrap." if lim.gci > 0 else "")
    return f"{lim.value:.6g} ± {lim.gci:.2g}{p}"


def markdown(rows, scenes, notes, reqs, elapsed, lims, ref_dir):
    """The text of reference/external.md."""
    out = ["# External codes on the continuous problem (issue 30 §3)", "",
           f"Generated by `{ENTRY}` (whole suite {elapsed:.0f} s on this machine, 2 cores shared). Codes: GetFEM 5.4.2",
           "(Debian python3-getfem, `make getfem`) with P1 and P2 Lagrange, its `add_normal_Dirichlet_condition_with_",
           "Nitsche_method` brick for u·n = g_n and a Nitsche Tresca term with GWFL's `Ball_projection`, solved by",
           "GetFEM's Newton; an independent conforming-P2 Nitsche solver in scikit-fem 12 (semismooth Newton,",
           "`tresca_py/external/skfem_nitsche.py`); on the near-incompressible scene cep also the mixed Taylor–Hood",
           "P2/P1 variants of both (getfem-TH: bulk and normal Nitsche term written in GWFL with σ(u, p) = 2μ ε(u)",
           "− p I; skfem-TH-nitsche: `tresca_py/external/skfem_mixed.py`), locking-free; tresca-cr (stabilised CR,",
           "`tresca-cr run`). Nitsche parameter p = γ_N (λ+2μ)/h with γ_N = 10 in every Nitsche code (GetFEM: h =",
           "its `element_size`; scikit-fem: the facet length). The P2 and TH codes run one level below the others",
           "(about equal DOF at the finest level). All codes of a scene use the same backward-Euler steps;",
           "quantities at T. Stick–slip endpoints: the ends of the last step's slip support at the threshold",
           "(h/|Γ_C|)² max|δu_τ|, zeros interpolated along Γ_C (`tresca_py/external/quantities.py`). max_slip:",
           "max |u·τ| over 513 samples of Γ_C. Limits: Richardson from each",
           "code's three finest levels with Roache's GCI (`tresca_py/external/richardson.py`): factor 1.25 with the",
           "observed order when the three values converge monotonically with p ≥ ½ and the fourth-finest level",
           "confirms p (GCI ratio within 10 %, as `tresca-cr study`), otherwise no extrapolation and the band",
           "3·max(|d₁|, |d₂|)/(2^p_th − 1) with the theoretical order p_th (the code's H1 order k; 2/3 for the",
           "endpoints on the scenes whose slip grows cubically from the fronts). Raw rows:",
           "`reference/external.csv`.",
           "",
           "Unilateral scenes (issue 40 item 5: sig_moving, sig_coulomb, coulomb_block): GetFEM P1/P2 with the",
           "Nitsche term (θ = 0) built on GWFL's `Coulomb_friction_coupled_projection` of σ(u)n − t_C at the gap",
           "g − u·n, the slip increment and r = 1/(γ₀h) (Tresca: f = [0, g_a, g_a]; Coulomb: f = F), the scikit-fem",
           "P2 solver extended to Signorini (`tresca_py/external/skfem_signorini.py`, Chouly–Hild–Renard Nitsche",
           "θ = 0, semismooth Newton) and tresca-cr. Two more quantities: normal_force = ∫_{Γ_C} p and",
           "max_pressure = max p (Nitsche: at the contact quadrature points; tresca-cr: over the edges, p_e),",
           "the latter with theoretical order k − ½ (a stress trace). Hertz (`hertz`): the Hertz study's meshes as",
           "levels (not `refine`), symmetry on the axis, a curved Γ_C (each edge's own normal), its own quantities",
           "(with half_width = 2√(∫p x²/∫p)) and no XO (no exact solution; verification/external/README.md).", ""]
    for sc in scenes:
        L = lims[sc.name]
        codes = sorted(L)
        out += [f"## {sc.name}: {sc.note}", "",
                (f"`{sc.path}`, refine {', '.join(map(str, sc.levels))}, " if sc.mesh_levels is None else
                 f"`{sc.path}` is level 0 of the mesh levels {', '.join(map(str, sc.levels))} (new meshes), ")
                + f"{sc.steps} step(s). "
                f"Command: `{ENTRY} --scene {sc.name}` (one code: add `--code CODE`).", ""]
        scene_notes = list(notes.get(sc.name, [])) + ([sc.remark] if sc.remark else [])
        if sc.locking:
            scene_notes.append("λ/μ = 10⁴: getfem-P1 is the locking witness (out of XA and XO: conforming P1's "
                               "asymptotic range needs h√(λ/μ) ≪ 1); the displacement-only P2 codes are in XA "
                               "but not XO; the Taylor–Hood codes carry XO (verification/external/README.md)")
        out += [f"- {n}" for n in scene_notes] + ([""] if scene_notes else [])
        out += ["| quantity | " + " | ".join(codes) + " |", "|---|" + "---|" * len(codes)]
        for q in sc.quantities:
            if q in UNILATERAL and not any(math.isfinite(L[c][q].value) for c in codes):
                continue  # a bilateral scene: no normal force or pressure reported
            out.append(f"| {q} | " + " | ".join(_fmt(L[c][q]) for c in codes) + " |")
        eo = error_orders(rows, sc.name)
        if eo:
            out += ["", "True H1-seminorm errors (at T) and observed orders:", "",
                    "| code | errors (coarse → fine) | successive orders | fit | theory |", "|---|---|---|---|---|"]
            for code, (succ, fit) in eo.items():
                errs = [r["err_h1_semi"] for r in by_code(rows, sc.name)[code]]
                out.append(f"| {code} | " + ", ".join(f"{e:.3e}" for e in errs) + " | "
                           + ", ".join(f"{s:.2f}" for s in succ) + f" | {fit:.2f} | {ORDER[code]} |")
        est = study_estimates(Path(ref_dir) / f"external_study_{sc.name}.csv")
        if est:
            out += ["", f"tresca-cr's own `study --csv` estimates (`reference/external_study_{sc.name}.csv`, "
                    f"`tresca-cr study {sc.path} --levels "
                    + ",".join(f"{r}:{sc.steps}" for r in sc.levels) + " --csv …`): "
                    + "; ".join(f"{q} {v}" for q, v in est.items()) + "."]
        out += ["", "| code | DOF (finest) | wall s (finest) |", "|---|---|---|"]
        for code, rs in by_code(rows, sc.name).items():
            out.append(f"| {code} | {rs[-1]['dofs']} | {rs[-1]['wall_s']:.3f} |")
        out.append("")
    out += cheapest(rows, scenes)
    out += ["## Requirements", "", "| id | requirement | result | detail |", "|---|---|---|---|"]
    out += [f"| {rid} | {text} | {'pass' if ok else '**FAIL**'} | {detail} |" for rid, text, ok, detail, _ in reqs]
    out += ["", "Plots: `reference/external_dof.png`, `reference/external_wall.png` (distance of ‖u_h‖_H1 to the",
            "common limit — the limit with the narrowest band — against DOF and against wall time).", ""]
    return "\n".join(out)


def cheapest(rows, scenes, target=1e-4):
    """Which code reaches a relative H1 error of ``target`` most cheaply, on the scenes with an exact solution."""
    out = [f"## Cost of {target:g} relative H1 accuracy", "",
           "Relative H1 error = |u − u_h|_H1 / ‖u_h‖_H1, on the scenes with an exact solution. Where no level",
           "reaches the target, DOF and wall time are extrapolated along the last two levels' log-log lines (≈;",
           "over decades, and with wall times measured on a shared machine, indicative only). Wall time: set-up,",
           "assembly and the time loop inside each code (no interpreter start, no post-processing).", "",
           "| scene | code | DOF | wall s | how |", "|---|---|---|---|---|"]
    for sc in scenes:
        best = None
        for code, rs in by_code(rows, sc.name).items():
            if "err_h1_semi" not in rs[-1]:
                continue
            for r in rs:
                r["rel"] = r["err_h1_semi"] / max(r["h1_norm"], 1e-300)
            dof, wall, how = cost_at(rs, target)
            mark = "" if how == "measured" else "≈ "
            out.append(f"| {sc.name} | {code} | {mark}{dof:.3g} | {mark}{wall:.3g} | {how} |")
            if math.isfinite(wall) and (best is None or wall < best[1]):
                best = (code, wall)
        if best:
            out.append(f"| {sc.name} | **cheapest: {best[0]}** | | {best[1]:.3g} | |")
    return out + [""]

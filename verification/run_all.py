"""make verify: every verification study of tresca-cr, its requirements checked pass/fail.

Runs the release binary's `study` subcommand on the manufactured cases and on the paper's Example 5.1,
writes tables (CSV + Markdown) and log-log plots into reference/, runs the independent Python solvers
and the comparisons, prints one summary table of requirements, and exits non-zero if any fails.

    .venv/bin/python verification/run_all.py [--quick] [--only NAME ...]

Every requirement states what the solver shall do, the command that checks it, and the reference file.
Observed orders: successive ratios log(e_i/e_{i+1})/log(h_i/h_{i+1}) and a least-squares fit over all
levels; a requirement on an order holds only if the fit AND the last two successive orders (the
asymptotic range) lie in the band.
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import time

import matplotlib

import estimates  # verification/estimates.py: Richardson/GCI estimates proved on the manufactured cases

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from tresca_py.common import BIN, PY, REF, ROOT, orders  # noqa: E402
RESULTS = []  # (requirement id, statement, passed, measured, command, reference file)


def require(rid, statement, passed, measured, command, ref_file):
    RESULTS.append((rid, statement, bool(passed), measured, command, ref_file))
    print(f"[{'PASS' if passed else 'FAIL'}] {rid}: {statement}\n        measured: {measured}")


def run(cmd, **kw):
    t = time.time()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stdout}\n{p.stderr}")
    return p.stdout, time.time() - t


def study(scene, levels, name, reference=None, solver=None, extra=()):
    """Run `tresca-cr study`, keep its CSV in reference/NAME.csv, return (rows, command).
    Numbers become floats, empty fields None, text fields (verdicts, size) stay strings."""
    out = os.path.join(REF, f"{name}.csv")
    cmd = [BIN, "study", scene, "--levels", ",".join(f"{r}:{n}" for r, n in levels), "--csv", out]
    if reference:
        cmd += ["--reference", f"{reference[0]}:{reference[1]}"]
    if solver:
        cmd += ["--solver", solver]
    cmd += list(extra)
    text, wall = run(cmd)
    print(text)
    rows = list(csv.DictReader(open(out)))

    def value(v):
        if v == "":
            return None
        try:
            return float(v)
        except ValueError:
            return v

    for r in rows:
        for k, v in r.items():
            r[k] = value(v)
    return rows, " ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd)


def rate_ok(x, e, p, tol):
    succ, fit = orders(x, e)
    ok = len(e) >= 4 and abs(fit - p) <= tol and all(abs(s - p) <= tol for s in succ[-2:])
    return ok, f"fit {fit:.3f}, successive {', '.join(f'{s:.3f}' for s in succ)} ({len(e)} levels)"


def table_md(name, title, rows, cols, xcol="h"):
    """Markdown table with successive orders next to each error column."""
    lines = [f"## {title}", "", "| refine | N | h | k | DOF | " + " | ".join(f"{c} | order" for c in cols) + " |",
             "|" + "---|" * (5 + 2 * len(cols))]
    for i, r in enumerate(rows):
        cells = [f"{int(r['refine'])}", f"{int(r['steps'])}", f"{r['h']:.4e}", f"{r['k']:.4e}", f"{int(r['paper_dofs'])}"]
        for c in cols:
            v = r[c]
            o = "-"
            if i > 0 and v and rows[i - 1][c]:
                o = f"{math.log(rows[i - 1][c] / v) / math.log(rows[i - 1][xcol] / r[xcol]):.3f}"
            cells += [f"{v:.4e}" if v is not None else "-", o]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def plot(name, title, x, series, xlabel, slopes):
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    for label, e in series:
        ax.loglog(x, e, "o-", label=label)
    for p in slopes:
        e0 = series[0][1][0]
        ax.loglog(x, [e0 * (v / x[0]) ** p for v in x], "k--", lw=0.8, label=f"slope {p}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("error")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(REF, f"{name}.png"), dpi=120)
    plt.close(fig)


def write(name, text):
    with open(os.path.join(REF, name), "w") as f:
        f.write(text)


# ---------------------------------------------------------------------------------------------------
def h_study(rid, scene, name, levels, p_energy, p_l2, statement, l2_required=True):
    rows, cmd = study(scene, levels, name)
    h = [r["h"] for r in rows]
    en, l2 = [r["energy_max"] for r in rows], [r["l2_max"] for r in rows]
    ok_e, m_e = rate_ok(h, en, p_energy, 0.1)
    ok_l, m_l = rate_ok(h, l2, p_l2, 0.15)
    md = table_md(name, f"{scene}: true errors (max over time nodes)", rows, ["energy_max", "h1_max", "l2_max"])
    write(f"{name}.md", f"<!-- generated by verification/run_all.py: {cmd} -->\n" + md)
    plot(name, os.path.basename(scene), h, [("energy", en), ("L2", l2)], "h", [1, 2])
    require(rid + "-energy", statement + f": energy order {p_energy} ± 0.1", ok_e, m_e, cmd, f"reference/{name}.md")
    if l2_required:
        require(rid + "-L2", statement + f": L² order {p_l2} ± 0.15", ok_l, m_l, cmd, f"reference/{name}.md")
    else:
        print(f"        (L² reported, not required: {m_l})")
    return rows


def k_study(quick):
    """mms_stop: slip stops abruptly at t* = 1/3. N = 4^j keeps θ = frac(N t*) = 1/3, so the O(k) constant is
    fixed (with N = 2^j it alternates between 1/3 and 2/3 and successive orders alternate ≈ 0 and ≈ 2).
    The time error is measured against a same-mesh run with many steps (the semi-discrete solution at this h);
    the true error is reported beside it, with the spatial error it cannot go below."""
    r = 3
    levels = [(r, 4), (r, 16), (r, 64), (r, 256)]
    ref = (r, 1024 if quick else 4096)
    rows, cmd = study("verification/cases/mms_stop.toml", levels, "k_study_mms_stop", reference=ref)
    k = [x["k"] for x in rows]
    et = [x["reference_max"] for x in rows]
    en = [x["energy_max"] for x in rows]
    ok, m = rate_ok(k, et, 1.0, 0.1)
    md = table_md("k_study_mms_stop", f"mms_stop: time refinement at refine {r}; reference_max = max over the nodes of N = 4 of "
                  f"|||u_N − u_ref||| with u_ref the N = {ref[1]} solution on the same mesh; energy_max = true error, max over "
                  "each level's own nodes (\"max over n\", the paper's ℓ∞(0,T) norm), energy_common = max over the nodes of N = 4",
                  rows, ["reference_max", "energy_max", "energy_common", "l2_max"], xcol="k")
    write("k_study_mms_stop.md", f"<!-- generated by verification/run_all.py: {cmd} -->\n" + md)
    plot("k_study_mms_stop", "mms_stop: time error vs k (h fixed)", k, [("time error (vs N=%d)" % ref[1], et), ("true energy error", en)], "k", [1])
    require("K1-mms_stop", "backward Euler shall converge with order 1 ± 0.1 in k when slip stops abruptly (time error at fixed h)",
            ok, m, cmd, "reference/k_study_mms_stop.md")


def slip_to_stick_transitions(n_steps, refine=3):
    """Run mms_stick_to_slip with a results file; count discrete slip→stick transitions (edge-steps)."""
    import h5py
    import numpy as np
    h5 = os.path.join(ROOT, "out", f"stick_to_slip_{refine}_{n_steps}.h5")
    run([BIN, "run", "verification/cases/mms_stick_to_slip.toml", "--refine", str(refine), "--steps", str(n_steps), "-o", h5, "--force", "-q"])
    with h5py.File(h5) as f:
        st = f["tresca/contact/state"][:]
    return int(np.sum((st[1:-1] == 1) & (st[2:] == 0)))


def be_exact_study():
    """mms_stick_to_slip: the exact solution only passes from stick to slip. Backward Euler is exact at the
    nodes for the discrete problem as long as the DISCRETE solution does too (no edge slips and then sticks):
    then the solutions of different time grids coincide at common nodes up to rounding."""
    os.makedirs(os.path.join(ROOT, "out"), exist_ok=True)
    rows, cmd = study("verification/cases/mms_stick_to_slip.toml", [(3, 2), (3, 8), (3, 32), (3, 128)], "be_exact_stick_to_slip")
    back = {int(r["steps"]): slip_to_stick_transitions(int(r["steps"])) for r in rows}
    rel = [r["consecutive_max"] / r["norm_max"] for r in rows[1:]]
    monotone = [r for r in rows[1:] if back[int(r["steps"])] == 0]
    rel_mono = [r["consecutive_max"] / r["norm_max"] for r in monotone]
    md = table_md("be_exact_stick_to_slip", "mms_stick_to_slip at refine 3: consecutive_max = max over the nodes of N = 2 of "
                  "|||u_N − u_{N/4}|||", rows, ["consecutive_max", "energy_max", "l2_max"], xcol="k")
    md += "\n| N | discrete slip→stick transitions (edge-steps) | max |||u_N − u_{N/4}||| / |||u||| |\n|---|---|---|\n"
    for r in rows:
        n = int(r["steps"])
        c = "-" if r["consecutive_max"] is None else f"{r['consecutive_max'] / r['norm_max']:.2e}"
        md += f"| {n} | {back[n]} | {c} |\n"
    md += ("\nFinding: while the discrete solution only passes from stick to slip (N ≤ 32 here), the solutions of "
           "different time grids coincide at the common nodes to rounding: backward Euler is exact at the nodes. "
           "With N = 128 some edges at the discrete front slip in one step and stick in the next (the count above), "
           "and the solution moves away from the grid-independent one by the amount shown — still far below the "
           "spatial error.\n")
    write("be_exact_stick_to_slip.md", f"<!-- generated by verification/run_all.py: {cmd} -->\n" + md)
    ok = len(rel_mono) >= 2 and max(rel_mono) <= 1e-12
    require("K2-stick-to-slip", "while the discrete solution only passes from stick to slip, backward Euler shall be exact at the "
            "nodes: solutions of different time grids agree to rounding (≤ 1e-12 relative)", ok,
            "; ".join(f"N={int(r['steps'])}: {back[int(r['steps'])]} slip→stick, rel. diff {x:.1e}" for r, x in zip(rows[1:], rel, strict=False)),
            cmd, "reference/be_exact_stick_to_slip.md")


def joint_study(quick):
    # k ∝ h² (N = 4^j keeps θ = frac(N/3) fixed), starting at N = 16 so that the O(h) term leads from the
    # coarsest level on (time error ≈ 15 % of the total at refine 0, see reference/k_study_mms_stop.md)
    levels = [(0, 16), (1, 64), (2, 256), (3, 1024)]
    rows, cmd = study("verification/cases/mms_stop.toml", levels, "joint_mms_stop")
    h = [r["h"] for r in rows]
    en = [r["energy_max"] for r in rows]
    ok, m = rate_ok(h, en, 1.0, 0.1)
    write("joint_mms_stop.md", f"<!-- generated by verification/run_all.py: {cmd} -->\n" +
          table_md("joint_mms_stop", "mms_stop: joint refinement h → h/2, k → k/4", rows, ["energy_max", "l2_max"]))
    plot("joint_mms_stop", "mms_stop: joint refinement (k ∝ h²)", h, [("energy", en)], "h", [1])
    # the same with N = 4^j from N = 1: the time term leads on coarse levels (reported, not required)
    pre, _ = study("verification/cases/mms_stop.toml", [(0, 1), (1, 4), (2, 16), (3, 64)], "joint_mms_stop_from_n1")
    s_pre, f_pre = orders([r["h"] for r in pre], [r["energy_max"] for r in pre])
    print(f"        (joint from N = 1: fit {f_pre:.3f}, successive {', '.join(f'{x:.3f}' for x in s_pre)}: pre-asymptotic, time error leads)")
    require("J1-joint", "under joint refinement the energy error shall converge with order 1 ± 0.1 in h", ok, m, cmd,
            "reference/joint_mms_stop.md")


def paper_tables(quick):
    """Tables 5.1 and 5.2 of the paper: consecutive-level errors, orders recomputed, and our true error."""
    paper = [r for r in csv.DictReader(line for line in open(os.path.join(REF, "paper_tables.csv")) if not line.startswith("#"))]
    t1 = [r for r in paper if r["table"] == "5.1"]
    t2 = [r for r in paper if r["table"] == "5.2"]

    def rec(rows, kind):
        e = [float(r["error"]) for r in rows]
        dof = [int(r["DOF"]) for r in rows]
        if kind == "log2":
            return [None] + [math.log2(e[i - 1] / e[i]) for i in range(1, len(e))]
        return [None] + [math.log(e[i - 1] / e[i]) / math.log(math.sqrt(dof[i] / dof[i - 1])) for i in range(1, len(e))]

    o1 = rec(t1, "dof")
    o2 = rec(t2, "log2")
    t2c = [dict(r, error="7.410e-5") if r["N"] == "40" else r for r in t2]  # the misprint corrected
    o2c = rec(t2c, "log2")

    def fmt(v):
        return "-" if v is None else f"{v:.4e}"

    expected1 = [0.8577, 0.9671, 0.9015, 0.866]
    ok_rec = all(abs(a - b) < 6e-4 for a, b in zip(o1[1:], expected1, strict=False))
    ref_level = (6, 2560) if quick else (7, 5120)
    rows1, cmd1 = study("verification/cases/paper_example_5_1.toml", [(k, 40 << k) for k in range(5)], "paper_table_5_1",
                        reference=ref_level)
    rows2, cmd2 = study("verification/cases/paper_example_5_1.toml", [(0, 10)] + [(k, 20 << (k - 1)) for k in range(1, 6)], "paper_table_5_2")
    rows2 = rows2[1:]  # n = 2 only provides the consecutive error of the n = 4 row
    lines = ["<!-- generated by verification/run_all.py -->", "# Example 5.1: the paper's Tables 5.1 and 5.2 reproduced", "",
             f"Commands: `{cmd1}` and `{cmd2}`.", "",
             "Consecutive error: |||u_l(T) − P u_{l−1}(T)|||, energy norm (with the jump term) of level l, P = CR interpolation",
             "of the coarse solution on the fine mesh, at the final time T = 1, as the paper describes. Orders recomputed:",
             "Table 5.1 as log(e1/e2)/log(√(DOF2/DOF1)), Table 5.2 as log2(e1/e2).", "",
             "## Table 5.1 (N = 20n)", "",
             "| N | n | DOF | paper error | paper order (printed) | paper order (recomputed) | our consecutive error | our order | our true error vs reference | order |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for i, (p, r) in enumerate(zip(t1, rows1, strict=False)):
        oc = "-" if i == 0 else f"{math.log(rows1[i - 1]['consecutive_T'] / r['consecutive_T']) / math.log(math.sqrt(r['paper_dofs'] / rows1[i - 1]['paper_dofs'])):.4f}" if r["consecutive_T"] and rows1[i - 1]["consecutive_T"] else "-"
        orf = "-" if i == 0 else f"{math.log(rows1[i - 1]['reference_T'] / r['reference_T']) / math.log(rows1[i - 1]['h'] / r['h']):.4f}"
        lines.append(f"| {p['N']} | {2 << i} | {int(r['paper_dofs'])} | {p['error']} | {p['order'] or '-'} | "
                     f"{'-' if o1[i] is None else f'{o1[i]:.4f}'} | {fmt(r['consecutive_T'])} | {oc} | {r['reference_T']:.4e} | {orf} |")
    lines += ["", "## Table 5.2 (N = 5n)", "",
              "| N | n | DOF | paper DOF | paper error | paper order (printed) | paper order (recomputed) | recomputed with 7.410e-5 | our consecutive error | our order | ours with N = 20n (Table 5.1) |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
    for i, (p, r, r1) in enumerate(zip(t2, rows2, rows1[1:] + [{"consecutive_T": None}], strict=False)):
        oc = "-" if i == 0 else f"{math.log2(rows2[i - 1]['consecutive_T'] / r['consecutive_T']):.4f}"
        lines.append(f"| {p['N']} | {4 << i} | {int(r['paper_dofs'])} | {p['DOF']} | {p['error']} | {p['order'] or '-'} | "
                     f"{'-' if o2[i] is None else f'{o2[i]:.4f}'} | {'-' if o2c[i] is None else f'{o2c[i]:.4f}'} | {fmt(r['consecutive_T'])} | {oc} | {fmt(r1['consecutive_T'])} |")
    e32, e16, c32 = rows1[4]["reference_T"], rows1[3]["reference_T"], rows1[4]["consecutive_T"]
    same = all(abs(a["consecutive_T"] - b["consecutive_T"]) <= 1e-12 * a["consecutive_T"] for a, b in zip(rows1[1:], rows2[:-1], strict=False))
    lines += ["", "## What the consecutive-mesh error hides", "",
              f"* **The time step plays no role in Example 5.1.** Our Table 5.2 column (N = 5n) equals our Table 5.1 column (N = 20n) "
              f"{'to 1e-12' if same else '(NOT equal: check)'}: points of Γ_C only pass from stick to slip (all of Γ_C slips by t = 0.025 at "
              "every level and keeps slipping under loads proportional to t), so backward Euler is exact at the nodes and the 'order in k' of Table 5.2 is an order in h.",
              f"* **It is an error of the coarser level, measured late.** The row n = 32 reports |||u_32 − P u_16||| = {c32:.3e}, between the "
              f"true errors of n = 16 ({e16:.3e}) and n = 32 ({e32:.3e}); it estimates neither, and its order equals the true order only "
              "once both levels are asymptotic.",
              "* **Its size depends on P.** The prolongation of a CR function to the finer mesh is not conforming, and its jumps are "
              "charged with the finer level's penalty 2ρμ/h; the true error (against a reference, with the coarse level's own jumps) "
              "has no such term.",
              "* **Magnitudes.** Our errors are about 20–25 times the paper's at every level while the orders agree; the paper's norm or "
              "scaling is not stated precisely enough to pin the factor down (its Uzawa also stopped at |Δu| < 1e-8, which on these "
              "meshes is not a converged multiplier)."]
    est = estimates.paper_estimate_rows(rows1)
    p_est, b_est = rows1[0]["p"], rows1[0]["beta"]
    lines += ["", "## The true error estimated without a reference run (issue 14)", "",
              f"`tresca-cr study` estimates the energy error of every level from the five levels alone (Richardson model of "
              f"src/study/richardson.rs, order p = {'-' if p_est is None else f'{p_est:.3f}'} and β = "
              f"{'-' if b_est is None else f'{b_est:.3f}'} from the three finest levels, at T). Next to it: the paper's number, our "
              "consecutive error and our error against the n = 256, N = 5120 reference run (which costs more than the whole study).", "",
              "| n | N | paper error | our consecutive error | estimated true error | error vs reference | estimate / reference | verdict |",
              "|---|---|---|---|---|---|---|---|"]
    for (n, e_t, ref_t, con_t, verdict), p in zip(est, t1, strict=False):
        ratio = "-" if e_t is None else f"{e_t / ref_t:.3f}"
        lines.append(f"| {n} | {p['N']} | {p['error']} | {fmt(con_t)} | {fmt(e_t)} | {ref_t:.4e} | {ratio} | {verdict} |")
    e32_est = est[-1][1]
    rel32 = estimates.relative(e32_est, est[-1][2]) if e32_est is not None else float("inf")
    lines += ["", "What the estimate tells that the paper's tables do not:", "",
              f"* the true error of the n = 32 level is about {fmt(e32_est)}, not the {c32:.3e} of the consecutive column (that "
              "is a distance between two levels and is charged with the finer level's penalty on the coarse jumps);",
              f"* the order is {'-' if p_est is None else f'{p_est:.2f}'}, below the 1 of the theory for H² solutions and stable "
              "from level to level: the corners of Γ_D with Γ_N and Γ_C limit the regularity, so refining by 2 gains a factor "
              f"{'-' if p_est is None else f'{2 ** p_est:.2f}'}, not 2 — a consecutive column decreasing like this is not pre-asymptotic "
              "noise but the singularity's rate;",
              "* the GCI (1.25 × estimate) is an error band a user can quote without any finer run."]
    write("paper_tables.md", "\n".join(lines) + "\n")
    require("P3-paper-estimate", "Example 5.1: the error of the n = 32 level estimated from the five levels of Table 5.1 alone shall agree "
            "with its error against the n = 256 reference run within 20 %", rel32 <= 0.2,
            f"estimate {fmt(e32_est)} vs reference {est[-1][2]:.4e}: {100 * rel32:.1f} % ({est[-1][4][:60]})", cmd1,
            "reference/paper_tables.md")
    require("P1-paper-orders", "the paper's Table 5.1 orders recomputed from its errors shall be 0.8577, 0.9671, 0.9015, 0.866 (as stated in issue 5)",
            ok_rec, ", ".join(f"{v:.4f}" for v in o1[1:]), "verification/run_all.py (paper_tables)", "reference/paper_tables.md")
    h = [r["h"] for r in rows1]
    e = [r["reference_T"] for r in rows1]
    c = [r["consecutive_T"] for r in rows1[1:]]
    plot("paper_table_5_1", "Example 5.1 (N = 20n): error at T", h, [("true (vs reference)", e)], "h", [1])
    fig = plt.figure()
    plt.close(fig)
    require("P2-paper-runs", "Example 5.1 shall run on the paper's meshes and steps with every step converged, "
            "consecutive and reference errors decreasing", all(e[i] > e[i + 1] for i in range(len(e) - 1)) and all(c[i] > c[i + 1] for i in range(len(c) - 1)),
            f"true errors {', '.join(f'{v:.3e}' for v in e)}; consecutive {', '.join(f'{v:.3e}' for v in c)}", cmd1, "reference/paper_tables.md")


def fuzz(quick):
    cases = 2000 if quick else 20000
    env = dict(os.environ, TRESCA_FUZZ_CASES=str(cases))
    cmd = ["cargo", "test", "--release", "--test", "fuzz", "--", "--nocapture"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, env=env)
    lines = [line for line in p.stdout.splitlines() if line.startswith("fuzz ")]
    print("\n".join(lines))
    write("fuzz.md", "<!-- generated by verification/run_all.py -->\n# Fuzzing (proptest)\n\n`TRESCA_FUZZ_CASES=%d %s`\n\n" % (cases, " ".join(cmd))
          + "\n".join(f"- {line}" for line in lines) + "\n")
    require("F1-fuzz", f"the scene parser, expression evaluation and Gmsh reader shall not panic on {cases} fuzzed inputs each",
            p.returncode == 0 and len(lines) == 3, "; ".join(lines) if lines else p.stderr[-300:], f"TRESCA_FUZZ_CASES={cases} " + " ".join(cmd), "reference/fuzz.md")


def results_clients():
    """A results file opened by VTK's vtkHDFReader, meshio (XDMF) and h5py, values checked."""
    os.makedirs(os.path.join(ROOT, "out"), exist_ok=True)
    h5 = os.path.join("out", "verify_ex51.h5")
    cmd = [BIN, "run", "verification/cases/paper_example_5_1.toml", "--refine", "2", "--steps", "160", "-o", h5, "--force", "-q"]
    run(cmd)
    chk = [PY, "scripts/check_results.py", h5]
    p = subprocess.run(chk, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-2000:])
    require("O1-clients", "VTK (vtkHDFReader), meshio (XDMF) and h5py shall open the results file and read the solver's values",
            p.returncode == 0, (p.stdout.strip().splitlines() or ["(no output)"])[-1][:200], " ".join(chk), "scripts/check_results.py")
    chk = [PY, "verification/interrupted_runs.py"]
    p = subprocess.run(chk, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    require("O2-interrupted", "the files of a killed, a stopped and a resumed run shall open in VTK, meshio and h5py, "
            "each showing exactly its committed steps; a run killed while building a new file over a "
            "complete one shall leave the old run.h5 and run.xdmf unchanged", p.returncode == 0,
            (p.stdout.strip().splitlines() or ["(no output)"])[-1][:200], " ".join(chk), "verification/interrupted_runs.py")


def paraview():
    """Debian's ParaView (installed by `make paraview`) on finished, killed and resumed runs (issue 17)."""
    cmd = [PY, "verification/paraview_check.py"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    lines = p.stdout.strip().splitlines() or ["(no output)"]
    version = next((line for line in lines if line.startswith("ParaView:")), "ParaView: ?")
    pictures = [line.split("picture ")[1][:120] for line in lines if "picture out/" in line]
    require("V1-paraview", "ParaView's XDMFReader, Xdmf3ReaderS and Xdmf3ReaderT shall open the files of a finished, a killed and a "
            "resumed run as body and contact-line blocks with /tresca's values at two times, and scripts/paraview_view.py shall "
            "render a picture showing the body and the contact line", p.returncode == 0,
            f"{version}; {lines[-1][:80]}; " + "; ".join(pictures)[:300], " ".join(cmd[1:]), "out/paraview/*.png")


def cross_check(quick):
    out = os.path.join(ROOT, "out", "cross_check.json")
    script = os.path.join(ROOT, "verification", "cross_check.py")
    if not os.path.exists(script):
        require("X0-cross-check", "the independent scikit-fem and dolfinx solutions shall be compared", False, "verification/cross_check.py missing", "-", "-")
        return
    cmd = [PY, "verification/cross_check.py", "--json", out] + (["--quick"] if quick else [])
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-4000:])
    import json
    try:
        reqs = json.load(open(out))
    except Exception as e:  # noqa: BLE001
        require("X0-cross-check", "the cross-check shall produce its requirement list", False, f"{e}; {p.stderr[-300:]}", " ".join(cmd), "-")
        return
    for r in reqs:
        require(r["id"], r["statement"], r["passed"], r["measured"], r["command"], r.get("reference", "reference/cross_check.md"))


def script_requirements(cmd, out, rid0, what, default_ref, keep=lambda r: True):
    """Run a check script that writes its requirement list as JSON to `out` (removed first, so a crashed
    run cannot report a stale list) and record every requirement `keep` accepts."""
    if os.path.exists(out):
        os.remove(out)
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    import json
    try:
        reqs = json.load(open(out))
    except Exception as e:  # noqa: BLE001
        require(rid0, f"the {what} check shall produce its requirement list", False, f"{e}; {p.stderr[-300:]}",
                " ".join(cmd), "-")
        return
    for r in filter(keep, reqs):
        require(r["id"], r["statement"], r["passed"], r["measured"], r["command"], r.get("reference", default_ref))


def distributed(quick):
    """The distributed dolfinx/PETSc route (issue 16): D1 agreement at -n 1, 2, 3; D2 memory (full run only)."""
    out = os.path.join(ROOT, "out", "distributed.json")
    cmd = [PY, "verification/distributed.py", "--json", out, "--bin", BIN] + \
        (["--md", os.path.join(ROOT, "out", "distributed_quick.md")] if quick else ["--memory"])
    script_requirements(cmd, out, "D0-distributed", "distributed", "reference/distributed.md")


def planner(quick):
    """The planner against the truth (issue 15): verification/planner.py, PL1-PL4 per manufactured case. With
    --quick PL4 is left out: the planner's share is a claim about fine targets, which --quick does not reach."""
    out = os.path.join(ROOT, "out", "planner.json")
    cmd = [PY, "verification/planner.py", "--json", out] + \
        (["--quick", "--md", os.path.join(ROOT, "out", "planner_quick.md")] if quick else [])
    script_requirements(cmd, out, "PL0-planner", "planner", "reference/planner.md",
                        keep=lambda r: not (quick and r["id"].startswith("PL4")))


def stability():
    """Stability at the extremes (issue 7): verification/stability.py, one requirement per case."""
    cmd = [PY, "verification/stability.py"]
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    print(p.stdout[-3000:])
    cases = list(dict.fromkeys(line for line in p.stdout.splitlines() if line.startswith("[PASS]") or line.startswith("[FAIL]")))
    for i, line in enumerate(cases):
        require(f"S{i + 1}-stability", line[7:].strip()[:160], line.startswith("[PASS]"), "see reference/stability.md", " ".join(cmd[1:]),
                "reference/stability.md")
    if not cases:
        require("S0-stability", "the stability study shall run", False, p.stderr[-300:], " ".join(cmd[1:]), "reference/stability.md")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller levels (for make test)")
    ap.add_argument("--only", nargs="*", help="run only these studies")
    args = ap.parse_args()
    os.makedirs(REF, exist_ok=True)
    studies = {
        "elastic": lambda: (
            h_study("E1-rect", "verification/cases/elastic_rect.toml", "h_elastic_rect", [(k, 1) for k in range(2, 7)], 1, 2,
                    "the CR solver shall converge on a smooth elasticity problem (rectangle)"),
            h_study("E2-rotated", "verification/cases/elastic_rotated.toml", "h_elastic_rotated", [(k, 1) for k in range(2, 7)], 1, 2,
                    "the CR solver shall converge on a smooth elasticity problem (rotated square)")),
        "front": lambda: h_study("C1-front", "verification/cases/mms_front.toml", "h_mms_front",
                                 [(k, 64) for k in range(0, 4 if args.quick else 5)], 1, 2,
                                 "with a moving stick–slip front the solver shall converge in h", l2_required=False),
        "rotated": lambda: h_study("C2-rotated", "verification/cases/mms_rotated.toml", "h_mms_rotated",
                                   [(k, 16) for k in range(0, 4 if args.quick else 5)], 1, 2,
                                   "with contact on a non-axis-aligned edge the solver shall converge in h", l2_required=False),
        "k": lambda: k_study(args.quick),
        "be_exact": be_exact_study,
        "joint": lambda: joint_study(args.quick),
        "paper": lambda: paper_tables(args.quick),
        "estimates": lambda: estimates.run(study, require, write, args.quick),
        "planner": lambda: planner(args.quick),
        "clients": results_clients,
        "paraview": paraview,
        "stability": stability,
        "cross": lambda: cross_check(args.quick),
        "distributed": lambda: distributed(args.quick),
        "fuzz": lambda: fuzz(args.quick),
    }
    t0 = time.time()
    for name, fn in studies.items():
        if args.only and name not in args.only:
            continue
        try:
            fn()
        except Exception as e:  # a study that cannot run is a failed requirement, not a crash
            require(f"{name}-run", f"study `{name}` shall run", False, str(e).splitlines()[0][:300], "verification/run_all.py", "-")
    version = subprocess.run([BIN, "--version"], capture_output=True, text=True).stdout.strip()
    pyv = subprocess.run([PY, "-c", "import skfem, dolfinx_solver, dolfinx, numpy, scipy, sympy; print('scikit-fem', skfem.__version__, "
                          "'dolfinx', dolfinx.__version__, 'numpy', numpy.__version__, 'scipy', scipy.__version__, 'sympy', sympy.__version__)"],
                         capture_output=True, text=True).stdout.strip()
    lines = ["<!-- generated by verification/run_all.py -->", "# Verification summary", "",
             f"Machine: {os.uname().nodename}, {os.cpu_count()} cores; total {time.time() - t0:.0f} s. Versions: {version}; {pyv}.", "",
             "| requirement | statement | result | measured | command | reference |", "|---|---|---|---|---|---|"]
    for rid, st, ok, m, cmd, ref in RESULTS:
        lines.append(f"| {rid} | {st} | {'PASS' if ok else 'FAIL'} | {m} | `{cmd}` | {ref} |")
    if args.only:  # a partial run does not replace the committed summary
        with open(os.path.join(ROOT, "out", "summary_partial.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
    else:
        write("summary.md", "\n".join(lines) + "\n")
    print("\n" + "=" * 100 + "\nSUMMARY")
    for rid, _st, ok, m, _, _ in RESULTS:
        print(f"  {'PASS' if ok else 'FAIL'}  {rid:<22} {m[:70]}")
    failed = [r for r in RESULTS if not r[2]]
    print(f"{len(RESULTS) - len(failed)} passed, {len(failed)} failed, {time.time() - t0:.0f} s")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()

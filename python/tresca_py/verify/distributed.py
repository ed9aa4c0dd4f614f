"""The distributed dolfinx + PETSc/MUMPS route (issue 16): agreement (D1) and memory spreading (D2).

    .venv/bin/python verification/distributed.py [--memory] [--bin target/release/tresca-cr]
                                                 [--json out/distributed.json] [--md reference/distributed.md]

D1 (quick, about 8 min on 2 cores): every cross-check scene (verification/cases/*.toml and the generated expression
scenes of verification/cross_check.py) at its quick level, plus a Gmsh scene (verification/cases/lshape.msh,
refine 1, contact on its floor; once more with boundary data), is solved by the Rust binary and by
scripts/dolfinx_distributed.py under `mpirun -n 1`, `-n 2` and `-n 3` (3 is oversubscribed on 2 cores);
each distributed run is compared with the Rust run by scripts/compare.py: DOF vectors, energies, σ_τ and
true errors within 1e-8 relative at every time node, identical stick/slip sets. The boundary-data scenes
(``DATA_CASES``: dirichlet `u`, contact `gap`) are among them; D1 fails if one of them is not run.

D2 (--memory, ~6 min): Example 5.1 at refine 8 (1,574,912 unknowns, 512 contact edges, 3 steps) under
`mpirun -n 1` and `-n 2`, each rank wrapped in `/usr/bin/time -f "RSS %M"`: the peak resident memory of
the largest rank at -n 2 must be at most 0.6 x the -n 1 peak; the two runs must agree to 1e-8.  Set-up
and per-step times and the MUMPS statistics (factor entries, flops) are recorded, and they feed the
scaling model written into the report.  Without --memory the last D2 measurement
(reference/distributed_memory.json) is reported as such, not re-measured.

Prints PASS/FAIL per requirement with the measured numbers, writes the requirement list (JSON, merged by
verification/run_all.py) and reference/distributed.md, and exits 1 if a requirement fails.
"""
import argparse
import datetime
import json
import math
import os
import re
import subprocess
import sys
import time

import h5py
import numpy as np

from tresca_py.common import MPIRUN, PY, ROOT, case  # noqa: E402
from tresca_py.common import cmdline  # noqa: E402
from tresca_py.common import run as common_run  # noqa: E402
from tresca_py.common import short_path as rel  # noqa: E402

from tresca_py import compare  # noqa: E402
from tresca_py.dolfinx_cr.distributed.output import setup_times  # noqa: E402
from tresca_py.verify.harness import Harness, out_dir  # noqa: E402
from tresca_py.verify import cross_check  # noqa: E402  (scenes, quick levels)

SCRIPT = os.path.join(ROOT, "scripts", "dolfinx_distributed.py")
MEM_JSON = os.path.join(ROOT, "reference", "distributed_memory.json")
SOLVER_JSON = os.path.join(ROOT, "reference", "distributed_solvers.json")
SOLVER_CASE = dict(case="paper_example_5_1", refine=5, steps=2)
# Agreement tolerance: the same 1e-8 as the cross-check (X…): far above the rounding of two direct
# solvers on these condition numbers (observed ~1e-13) and far below any discretisation effect.
TOL = 1e-8
# Memory: the bound: the largest rank at -n 2 holds at most 60 % of the -n 1 peak (perfect
# spreading would give 50 % plus the per-process constant of Python, dolfinx and PETSc, ~0.2 GB).
MEM_RATIO = 0.6
RANKS = (1, 2, 3)
# the boundary-data scenes (issue 30 §1: dirichlet `u`, contact `gap`): D1 must cover them, so a filter that
# drops them from the case list fails D1 instead of passing it silently
DATA_CASES = ("mms_data_front", "mms_data_cep", "mms_data_stop")
BIG = dict(case="paper_example_5_1", refine=8, steps=3)


GMSH_SCENE = """title = "L-shape Gmsh mesh (verification/cases/lshape.msh) with Tresca contact on its floor (verification/distributed.py)"
[mesh]
file = "{msh}"
[material]
E = 200.0
nu = 0.3
[[boundary]]
name = "clamp"
kind = "dirichlet"
[[boundary]]
name = "loaded"
kind = "neumann"
traction = ["0.02*t", "-0.03*t*x"]
[[boundary]]
name = "floor"
kind = "contact"
g_a = "0.001*(1+x)"
[time]
T = 1.0
steps = 8
"""


def gmsh_data_scene(text):
    """GMSH_SCENE with Dirichlet data on the clamp and an imposed normal displacement on the floor, consistent
    at their common vertex (0, 0) (u·n = -u_y = gap) and with u0 = 0 at t0 = 0."""
    out = text.replace('kind = "dirichlet"\n', 'kind = "dirichlet"\nu = ["0.001*t*y", "0.002*t*(1+x)"]\n')
    out = out.replace('g_a = "0.001*(1+x)"', 'g_a = "0.001*(1+x)"\ngap = "-0.002*t*(1+x)"')
    out = out.replace('on its floor (verification/distributed.py)', 'on its floor, boundary data (verification/distributed.py)')
    assert out.count("gap =") == 1 and out.count("u = [") == 1, "GMSH_SCENE changed: update gmsh_data_scene"
    return out


def run(cmd, timeout=600):
    """tresca_py.common.run without raising: a hang (e.g. one rank waiting for a dead one) becomes a failed
    process after `timeout` s."""
    try:
        return common_run(cmd, check=False, timeout=timeout)
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        return subprocess.CompletedProcess(cmd, -9, out, f"timed out after {timeout} s"), float(timeout)


def dist_cmd(scene, out, refine, steps, ranks, timed=False, extra=()):
    base = [SCRIPT, scene, "-o", out, "-q", "--refine", str(refine)] + (["--steps", str(steps)] if steps else [])
    pre = [MPIRUN, "-n", str(ranks)]
    if timed:
        pre += ["/usr/bin/time", "-f", "RSS %M KB wall %e s"]
    return pre + [PY] + base + list(extra)


def attrs(path):
    with h5py.File(path, "r") as f:
        return dict(f["tresca"].attrs)


def agreement(binary, work):
    """D1: rows (case, refine, steps, ranks, compare result or error)."""
    plan = dict(cross_check.QUICK)
    on_disk = sorted(f[:-5] for f in os.listdir(cross_check.CASES_DIR) if f.endswith(".toml"))
    for name in on_disk:
        plan.setdefault(name, ((0,), None))
    scenes = {n: os.path.join(cross_check.CASES_DIR, f"{n}.toml") for n in on_disk}
    scenes.update(cross_check.generated_scenes(work))
    # plus a Gmsh scene (the distributed script reads Gmsh files on rank 0 and distributes them)
    scenes["gmsh_lshape"] = os.path.join(work, "gmsh_lshape.toml")
    with open(scenes["gmsh_lshape"], "w") as f:
        f.write(GMSH_SCENE.format(msh=case("lshape")[:-5] + ".msh"))
    plan["gmsh_lshape"] = ((1,), None)
    # and the same Gmsh scene with boundary data (each rank lifts its owned edges of a distributed Gmsh mesh)
    scenes["gmsh_lshape_data"] = os.path.join(work, "gmsh_lshape_data.toml")
    with open(scenes["gmsh_lshape_data"], "w") as f:
        f.write(gmsh_data_scene(GMSH_SCENE.format(msh=case("lshape")[:-5] + ".msh")))
    plan["gmsh_lshape_data"] = ((1,), None)
    rows, commands = [], []
    for name, (levels, steps) in plan.items():
        k = levels[0]
        tag = f"{name}_r{k}" + (f"_n{steps}" if steps else "")
        rs = os.path.join(work, f"{tag}_rust.h5")
        cmd = [binary, "run", scenes[name], "-o", rs, "--force", "-q", "--refine", str(k)] + \
              (["--steps", str(steps)] if steps else [])
        p, _ = run(cmd)
        commands.append(cmdline(cmd))
        if p.returncode != 0:
            rows.append(dict(case=name, refine=k, steps=steps, ranks="all", r=None,
                             err=f"rust failed: {(p.stderr or p.stdout).strip()[-300:]}"))
            continue
        for n in RANKS:
            out = os.path.join(work, f"{tag}_dist_np{n}.h5")
            cmd = dist_cmd(scenes[name], out, k, steps, n)
            p, wall = run(cmd)
            commands.append(cmdline(cmd))
            if p.returncode != 0:
                rows.append(dict(case=name, refine=k, steps=steps, ranks=n, r=None, wall=wall,
                                 err=f"distributed -n {n} failed: {(p.stderr or p.stdout).strip()[-300:]}"))
            else:
                try:
                    r = compare.compare_files(rs, out)
                    rows.append(dict(case=name, refine=k, steps=r["n_times"] - 1, ranks=n, r=r, wall=wall, err=None,
                                     file=out))
                except compare.CompareError as e:
                    rows.append(dict(case=name, refine=k, steps=steps, ranks=n, r=None, wall=wall, err=str(e)))
                commands.append(f".venv/bin/python scripts/compare.py {rel(rs)} {rel(out)} --strict-flags")
            row = rows[-1]
            print(f"  [{'PASS' if row_ok(row) else 'FAIL'}] {tag} -n {n}: {fmt(row)}", flush=True)
    return rows, commands


def vtk_check(h5path):
    """The parallel VTK output (OUT_vtk/displacement.pvd -> per-rank .vtu pieces) opened with VTK's
    vtkXMLPUnstructuredGridReader: at the last frame, the mean of the two vertex values of every edge of
    every non-ghost cell (a discontinuous P1 field's value at the edge midpoint) must equal the CR value
    u^N of the results file at that midpoint.  Returns (ok, message)."""
    import glob
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError as e:
        return False, f"vtk not importable: {e}"
    from scipy.spatial import cKDTree
    base = os.path.splitext(h5path)[0] + "_vtk"
    files = sorted(glob.glob(os.path.join(base, "displacement*.pvtu")))
    if not files:
        return False, f"no .pvtu files in {rel(base)}"
    r = vtk.vtkXMLPUnstructuredGridReader()
    r.SetFileName(files[-1])
    r.Update()
    g = r.GetOutput()
    X = vtk_to_numpy(g.GetPoints().GetData())[:, :2]
    U = vtk_to_numpy(g.GetPointData().GetArray("displacement"))[:, :2]
    cells = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 3)
    gh = g.GetCellData().GetArray("vtkGhostType")
    if gh is not None:
        cells = cells[vtk_to_numpy(gh) == 0]
    a, b = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]).T
    mid, val = 0.5 * (X[a] + X[b]), 0.5 * (U[a] + U[b])
    with h5py.File(h5path, "r") as f:
        M = f["tresca/mesh/midpoints"][()]
        u = f["tresca/u"][-1]
        ntri = f["tresca/mesh/triangles"].shape[0]
    dist, idx = cKDTree(M).query(mid)
    scale = max(float(np.max(np.abs(u))), 1e-300)
    err = float(np.max(np.abs(val - u[idx]))) / scale
    # tolerance: the pieces are ASCII with 16 significant digits, so midpoint means carry ~1e-15 relative
    # rounding; 1e-12 leaves room and still catches any wrong value, ordering or ghost handling
    ok = len(cells) == ntri and float(np.max(dist)) < 1e-9 and err <= 1e-12 and len(np.unique(idx)) == len(M)
    return ok, (f"{rel(files[-1])}: {len(cells)} non-ghost cells (results file: {ntri}), "
                f"edge-midpoint means vs u^N: max rel. diff {err:.1e}, every edge seen: {len(np.unique(idx)) == len(M)}")


def row_ok(row):
    r = row.get("r")
    return r is not None and max(r["du"], r["dE"], r["dsig"], r["derr"]) <= TOL and r["flags"] == 0


def fmt(row):
    r = row.get("r")
    if r is None:
        return row.get("err") or "not comparable"
    s = f"du {r['du']:.1e}, dE {r['dE']:.1e}, dsig {r['dsig']:.1e}"
    if r["has_errors"]:
        s += f", derr {r['derr']:.1e}"
    return s + f", flags {r['flags']}"


def parse_rss(stderr):
    """Per-rank peak RSS (MB) from the `/usr/bin/time -f "RSS %M KB ..."` lines, one per rank."""
    return [int(m) / 1024.0 for m in re.findall(r"RSS (\d+) KB", stderr)]


def memory(work, binary, with_rust):
    """D2: the big case at -n 1 and -n 2; returns a dict of measurements."""
    scene = os.path.join(cross_check.CASES_DIR, f"{BIG['case']}.toml")
    meas = dict(case=BIG["case"], refine=BIG["refine"], steps=BIG["steps"], runs={}, commands=[],
                date=datetime.date.today().isoformat(), load_before=os.getloadavg()[1])
    for n in (1, 2):
        out = os.path.join(work, f"big_np{n}.h5")
        cmd = dist_cmd(scene, out, BIG["refine"], BIG["steps"], n, timed=True, extra=["--frame-every", "0"])
        print(f"  running {cmdline(cmd)}", flush=True)
        p, wall = run(cmd, timeout=3600)
        meas["commands"].append(cmdline(cmd))
        if p.returncode != 0:
            meas["runs"][str(n)] = dict(error=(p.stderr or p.stdout).strip()[-400:])
            print(f"  -n {n} FAILED: {meas['runs'][str(n)]['error']}", flush=True)
            continue
        a = attrs(out)
        rss = parse_rss(p.stderr)
        meas["runs"][str(n)] = dict(
            wall=wall, rss_time_mb=rss, rss_self_mb=[float(x) for x in np.atleast_1d(a["peak_rss_mb"])],
            setup_time=float(a["setup_time"]), setup_times=setup_times(a),
            setup_peak_mb=json.loads(a["setup_peak_rss_mb"]), step_median=float(a["step_time_median"]),
            total=float(a["total_time"]), unknowns=int(a["n_dofs"]), n_contact=int(a["n_contact"]),
            mumps=json.loads(a["mumps"]), file=rel(out))
        print(f"  -n {n}: RSS per rank {', '.join(f'{x:.0f}' for x in rss)} MB; set-up {a['setup_time']:.1f} s, "
              f"step {a['step_time_median']:.2f} s", flush=True)
    if all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2)):
        r = compare.compare_files(os.path.join(work, "big_np1.h5"), os.path.join(work, "big_np2.h5"))
        meas["agree_1_2"] = dict(du=r["du"], dE=r["dE"], dsig=r["dsig"], flags=r["flags"])
        meas["commands"].append(f".venv/bin/python scripts/compare.py {rel(os.path.join(work, 'big_np1.h5'))} "
                                f"{rel(os.path.join(work, 'big_np2.h5'))} --strict-flags")
    if with_rust:
        rs = os.path.join(work, "big_rust.h5")
        cmd = ["/usr/bin/time", "-f", "RSS %M KB wall %e s", binary, "run", scene, "-o", rs, "--force", "-q",
               "--refine", str(BIG["refine"]), "--steps", str(BIG["steps"]), "--frame-every", str(BIG["steps"])]
        print(f"  running {cmdline(cmd)}", flush=True)
        p, wall = run(cmd)
        meas["commands"].append(cmdline(cmd))
        if p.returncode == 0:
            rss = parse_rss(p.stderr)
            meas["rust"] = dict(wall=wall, rss_mb=rss[0] if rss else None)
            r = compare.compare_files(rs, os.path.join(work, "big_np2.h5"))
            meas["rust"]["agree_np2"] = dict(du=r["du"], dE=r["dE"], dsig=r["dsig"], flags=r["flags"])
            os.remove(rs)
    return meas


# --------------------------------------------------------------------------------------------------
# scaling model
# --------------------------------------------------------------------------------------------------
def scaling_model(meas):
    """Per-rank memory and times for 1e7 and 1e8 unknowns on 16..256 ranks, from the -n 1/-n 2 data.

    Two measured points split the largest rank's peak into m(P) = c + D/P: D spreads over the ranks, c
    does not.  c minus the import footprint b (measured before the mesh exists) is what every rank holds in
    proportion to the mesh although it should not (host-side MUMPS analysis, per-rank index maps of global
    size ...); the model lets it grow ∝ n on every rank, which is pessimistic.  D grows like the factor
    (∝ n log2 n, 2D nested dissection) and is split over P ranks with a load imbalance of 1.3.  Times scale
    from the 1-rank measurement: factorisation ∝ n^1.5, solves ∝ n log2 n, C ∝ n_c x solve (an upper bound:
    MUMPS prunes the tree for selected entries of the inverse), parallel efficiency 0.5.
    """
    r1, r2 = meas["runs"]["1"], meas["runs"]["2"]
    n0 = r1["unknowns"]
    m1, m2 = max(r1["rss_time_mb"]), max(r2["rss_time_mb"])
    D = 2.0 * (m1 - m2)               # m(P) = c + D/P through the two points
    c = m1 - D
    b = float(r1["setup_peak_mb"][0].get("start", 155.0))
    st1 = r1["setup_times"]
    t_fact1 = st1["factorisation"]
    t_cond1 = st1["condensation"]
    t_step1 = r1["step_median"]
    nc0 = r1["n_contact"]
    rows = []
    for n in (1e7, 1e8):
        g_mem = (n / n0) * (math.log2(n) / math.log2(n0))
        g_flop = (n / n0) ** 1.5
        nc = math.sqrt(n / 6.0)
        g_cond = (nc / nc0) * g_mem
        C_mb = nc * nc * 8 / 2 ** 20
        for P in (16, 32, 64, 128, 256):
            mem = b + max(c - b, 0.0) * (n / n0) + D * g_mem / P * 1.3 + C_mb
            rows.append(dict(n=n, P=P, mem_gb=mem / 1024, mem_spread_gb=(b + D * g_mem / P * 1.3 + C_mb) / 1024,
                             fact_s=t_fact1 * g_flop / (P * 0.5), cond_s=t_cond1 * g_cond / (P * 0.5),
                             step_s=t_step1 * g_mem / (P * 0.5), nc=nc, C_mb=C_mb))
    return dict(c_mb=c, D_mb=D, b_mb=b, rows=rows, n0=n0)


def solver_compare(work):
    """MUMPS Cholesky versus CG + GAMG (HYPRE is not in the wheel's PETSc) on the same case, -n 1:
    set-up, building C (MUMPS: selected inverse entries; CG: n_c solves), per-step time, iterations, memory."""
    scene = os.path.join(cross_check.CASES_DIR, f"{SOLVER_CASE['case']}.toml")
    res = dict(SOLVER_CASE, date=datetime.date.today().isoformat(), runs={}, commands=[])
    for k in ("mumps", "cg-gamg"):
        out = os.path.join(work, f"solver_{k}.h5")
        cmd = ["/usr/bin/time", "-f", "RSS %M KB wall %e s", PY, SCRIPT, scene, "-o", out, "-q", "--refine",
               str(SOLVER_CASE["refine"]), "--steps", str(SOLVER_CASE["steps"]), "--frame-every", "0", "--ksp", k]
        print(f"  running {cmdline(cmd)}", flush=True)
        p, wall = run(cmd, timeout=3600)
        res["commands"].append(cmdline(cmd))
        if p.returncode != 0:
            res["runs"][k] = dict(error=(p.stderr or p.stdout).strip()[-300:])
            continue
        a = attrs(out)
        res["runs"][k] = dict(wall=wall, rss_mb=parse_rss(p.stderr)[0], setup=setup_times(a),
                              step=float(a["step_time_median"]), solves=int(a["linear_solves"]),
                              its=int(a["ksp_iterations_max"]), unknowns=int(a["n_dofs"]), n_contact=int(a["n_contact"]))
    if all("error" not in r for r in res["runs"].values()) and len(res["runs"]) == 2:
        r = compare.compare_files(os.path.join(work, "solver_mumps.h5"), os.path.join(work, "solver_cg-gamg.h5"))
        res["agree"] = dict(du=r["du"], dE=r["dE"], dsig=r["dsig"], flags=r["flags"])
    with open(SOLVER_JSON, "w") as f:
        json.dump(res, f, indent=1)
    return res


def solver_table(res):
    md = ["", "## Linear solver: MUMPS Cholesky versus CG + GAMG", "",
          f"Example 5.1 at refine {res['refine']}, {res['steps']} steps, 1 rank, measured {res['date']} "
          "(`verification/distributed.py --solver-compare`; HYPRE and ML are not in the wheel's PETSc). CG stops at a "
          "relative residual of 1e-13 (needed for the 1e-8 agreement); C needs n_c CG solves, while MUMPS reads C off its "
          "factor as selected entries of K⁻¹.", "",
          "| solver | unknowns | n_c | set-up (factor / AMG) s | C s | per step s | iterations per solve | peak RSS MB | whole run s |",
          "|---|---|---|---|---|---|---|---|---|"]
    for k, r in res["runs"].items():
        if "error" in r:
            md.append(f"| {k} | failed: {r['error'][:100]} |||||||")
            continue
        md.append(f"| {k} | {r['unknowns']:,} | {r['n_contact']} | {r['setup']['factorisation']:.2f} | "
                  f"{r['setup']['condensation']:.2f} | {r['step']:.3f} | {r['its'] if k != 'mumps' else '– (direct)'} | "
                  f"{r['rss_mb']:.0f} | {r['wall']:.1f} |")
    if res.get("agree"):
        a = res["agree"]
        md += ["", f"The two agree: du {a['du']:.1e}, dE {a['dE']:.1e}, dsig {a['dsig']:.1e}, flags {a['flags']}."]
    md += ["", "Choice: MUMPS. CG + GAMG sets up faster and needs less memory, but every solve costs tens of "
           "iterations and C alone costs n_c ∝ √n solves, so the run is orders of magnitude slower, and the gap "
           "grows with the mesh (n_c and the iteration count both grow; MUMPS' selected-entries solve prunes its tree).",
           "", "```"] + res["commands"] + ["```"]
    return md


# --------------------------------------------------------------------------------------------------
def check_d1(hs, args, self_cmd):
    """D1: agreement with the Rust solver at -n 1, 2 and 3, and the VTK pieces read back; returns the rows
    and the commands."""
    t_start = time.perf_counter()
    print("D1: agreement with the Rust solver at -n 1, 2, 3", flush=True)
    rows, commands = agreement(args.bin, args.work)
    t_d1 = time.perf_counter() - t_start
    nfail = sum(not row_ok(r) for r in rows)
    worst = {k: max((r["r"][k] for r in rows if r.get("r")), default=float("nan")) for k in ("du", "dE", "dsig", "derr")}
    missing = [c for c in DATA_CASES if not any(r["case"] == c and r.get("r") for r in rows)]
    d1_ok = nfail == 0 and len(rows) > 0 and not missing
    d1_meas = (f"{len(rows) - nfail}/{len(rows)} runs agree; worst du {worst['du']:.1e}, dE {worst['dE']:.1e}, "
               f"dsig {worst['dsig']:.1e}, derr {worst['derr']:.1e}; {t_d1:.0f} s")
    if missing:
        d1_meas += f"; boundary-data scenes not run: {', '.join(missing)}"
    if nfail:
        d1_meas += "; failing: " + "; ".join(f"{r['case']} -n {r['ranks']}: {fmt(r)}" for r in rows if not row_ok(r))[:400]
    # the visualisation output of the last 3-rank run with contact (Example 5.1), read back with VTK
    vtk_h5 = next((r["file"] for r in rows if r["case"] == "paper_example_5_1" and r["ranks"] == 3 and r.get("file")),
                  None)
    vtk_ok, vtk_msg = vtk_check(vtk_h5) if vtk_h5 else (False, "no 3-rank run of paper_example_5_1")
    print(f"  [{'PASS' if vtk_ok else 'FAIL'}] VTK output: {vtk_msg}", flush=True)
    d1_ok = d1_ok and vtk_ok
    d1_meas += f"; VTK pieces of the -n 3 Example 5.1 run read back: {'ok' if vtk_ok else 'FAIL'} ({vtk_msg})"
    hs.require("D1-distributed-agree", d1_ok, d1_meas,
               statement=(f"the distributed dolfinx/PETSc route under mpirun -n 1, 2 and 3 shall agree with the Rust "
                          f"solver on every cross-check scene (quick level; the boundary-data scenes {', '.join(DATA_CASES)} "
                          f"among them) within {TOL:g} relative in u, energy, σ_τ and "
                          f"true errors at every time node, with identical stick/slip sets; its parallel VTK output "
                          f"(discontinuous P1) shall read back in VTK with the CR values at every edge midpoint"),
               command=self_cmd, reference="reference/distributed.md")
    return rows, commands


def check_d2(hs, args, self_cmd):
    """D2: the memory of -n 2 against -n 1 (measured with --memory, else the last measurement); returns it."""
    meas = None
    if args.memory:
        print("D2: memory at -n 1 and -n 2", flush=True)
        meas = memory(args.work, args.bin, args.with_rust)
        ok_runs = all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2))
        if ok_runs:
            meas["model"] = scaling_model(meas)
        with open(args.memory_json or MEM_JSON, "w") as f:
            json.dump(meas, f, indent=1)
    elif os.path.exists(MEM_JSON):
        with open(MEM_JSON) as f:
            meas = json.load(f)
    if meas is not None:
        ok_runs = all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2))
        if ok_runs:
            m1 = max(meas["runs"]["1"]["rss_time_mb"])
            m2 = max(meas["runs"]["2"]["rss_time_mb"])
            ag = meas.get("agree_1_2", {})
            agree_ok = ag and max(ag["du"], ag["dE"], ag["dsig"]) <= TOL and ag["flags"] == 0
            big_ok = meas["runs"]["1"]["unknowns"] >= 10 ** 6
            ok = m2 <= MEM_RATIO * m1 and agree_ok and big_ok
            d2_meas = (f"{meas['runs']['1']['unknowns']} unknowns: peak RSS -n 1 {m1:.0f} MB, -n 2 largest rank {m2:.0f} MB "
                       f"(ratio {m2 / m1:.2f}); -n 1 vs -n 2 du {ag.get('du', float('nan')):.1e}, flags {ag.get('flags')}")
        else:
            ok = False
            d2_meas = "; ".join(f"-n {n}: {r.get('error', 'ok')}" for n, r in meas["runs"].items())
        if not args.memory:
            d2_meas += f" (measured {meas['date']}, not re-run: give --memory)"
        hs.require("D2-distributed-memory", ok, d2_meas,
                   statement=(f"on ≥ 10⁶ unknowns the peak resident memory of the largest rank at mpirun -n 2 shall be "
                              f"at most {MEM_RATIO} × the -n 1 peak, the two runs agreeing within {TOL:g}"),
                   command=self_cmd + " --memory", reference="reference/distributed.md")
    return meas


def write_report(hs, args, self_cmd, rows, commands, meas, total):
    """The Markdown report and the requirement list."""
    md = ["<!-- generated by verification/distributed.py -->",
          "# The distributed route: dolfinx + PETSc/MUMPS (issue 16)", "",
          f"`{self_cmd}{' --memory' if args.memory else ''}` — {len(hs.results) - len(hs.failed)}/{len(hs.results)} "
          f"requirements passed, {total:.0f} s.", "",
          "| id | passed | measured |", "|---|---|---|"]
    md += [f"| {r.id} | {'PASS' if r.passed else 'FAIL'} | {r.measured} |" for r in hs.results]
    md += ["", "## D1: agreement with the Rust solver", "",
           "`scripts/dolfinx_distributed.py` under `mpirun -n P` against `tresca-cr run` on the cross-check scenes at their "
           "quick level (verification/cross_check.py QUICK). Max over the time nodes; du, dE, derr relative; dsig relative to "
           "max ḡ; flags = differing stick/slip states summed over the nodes. Tolerance 1e-8.", "",
           "| case | refine | N | ranks | du | dE | dsig | derr | flags | wall s | ok |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in rows:
        r = row.get("r")
        if r is None:
            md.append(f"| {row['case']} | {row['refine']} | {row['steps'] or '–'} | {row['ranks']} | – | – | – | – | – | – | FAIL: "
                      f"{(row.get('err') or '')[:120]} |")
            continue
        derr = f"{r['derr']:.1e}" if r["has_errors"] else "–"
        md.append(f"| {row['case']} | {row['refine']} | {row['steps']} | {row['ranks']} | {r['du']:.1e} | {r['dE']:.1e} | "
                  f"{r['dsig']:.1e} | {derr} | {r['flags']} | {row['wall']:.1f} | {'PASS' if row_ok(row) else 'FAIL'} |")
    if meas is not None and all(str(n) in meas["runs"] and "error" not in meas["runs"][str(n)] for n in (1, 2)):
        md += memory_tables(meas, args.memory)
    if os.path.exists(SOLVER_JSON):
        with open(SOLVER_JSON) as f:
            md += solver_table(json.load(f))
    md += ["", "## Commands (D1)", "", "Run from the repository root:", "", "```"] + commands + ["```", ""]
    os.makedirs(os.path.dirname(os.path.abspath(args.md)), exist_ok=True)
    with open(args.md, "w") as f:
        f.write("\n".join(md))
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    hs.dump(args.json)
    print(f"wrote {rel(os.path.abspath(args.md))} and {rel(os.path.abspath(args.json))}")
    return 1 if hs.failed else 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--memory", action="store_true", help="also run D2 (1.57M unknowns at -n 1 and -n 2, ~6 min)")
    ap.add_argument("--with-rust", action="store_true", help="with --memory: also run the Rust binary on the big case")
    ap.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "tresca-cr"),
                    help="the Rust binary (default target/release/tresca-cr)")
    ap.add_argument("--json", default=os.path.join(ROOT, "out", "distributed.json"), help="requirement list")
    ap.add_argument("--md", default=os.path.join(ROOT, "reference", "distributed.md"), help="Markdown report")
    ap.add_argument("--memory-json", help="with --memory: where the measurement goes (default "
                    "reference/distributed_memory.json; make verify stages it under out/verify/reference/)")
    ap.add_argument("--work", default=os.path.join(ROOT, "out", "distributed"), help="directory for results files")
    ap.add_argument("--solver-compare", action="store_true",
                    help="only measure MUMPS against CG + GAMG (reference/distributed_solvers.json, ~3 min) and exit")
    args = ap.parse_args(argv)
    if args.solver_compare:
        os.makedirs(args.work, exist_ok=True)
        print("\n".join(solver_table(solver_compare(args.work))))
        return 0
    if not os.path.exists(args.bin):
        sys.exit(f"error: Rust binary {args.bin} missing (cargo build --release, or give --bin)")
    if not os.path.exists(MPIRUN):
        sys.exit(f"error: {MPIRUN} missing (the venv's mpich wheel provides it)")
    os.makedirs(args.work, exist_ok=True)
    t_start = time.perf_counter()
    hs = Harness(out=os.path.join(out_dir(), "distributed_harness"))
    self_cmd = ".venv/bin/python verification/distributed.py"

    rows, commands = check_d1(hs, args, self_cmd)
    meas = check_d2(hs, args, self_cmd)
    return write_report(hs, args, self_cmd, rows, commands, meas, time.perf_counter() - t_start)


def memory_tables(meas, fresh):
    r1, r2 = meas["runs"]["1"], meas["runs"]["2"]
    md = ["", "## D2: memory and time at 1 and 2 ranks", "",
          f"Example 5.1 (`verification/cases/{meas['case']}.toml`) at refine {meas['refine']}: {r1['unknowns']:,} unknowns, "
          f"{r1['n_contact']} contact edges, {meas['steps']} steps, no visualisation frames. Measured {meas['date']}"
          f"{'' if fresh else ' (not re-run by this invocation; `--memory` re-measures)'}; the machine has 2 cores and "
          "other jobs may run beside it, so times vary" +
          (f" (5-minute load average {meas['load_before']:.1f} when D2 started)." if "load_before" in meas else ".") +
          " Memory does not depend on the load.", "",
          "Peak resident memory per rank, from `/usr/bin/time -f \"RSS %M\"` around each rank's process (one line per "
          "rank) and, beside it, the process's own `getrusage` maximum (the same quantity, recorded in the results file):", "",
          "| ranks | rank | peak RSS (time) MB | peak RSS (getrusage) MB | after mesh | after assembly | after factorisation | after C |",
          "|---|---|---|---|---|---|---|---|"]
    for n, r in (("1", r1), ("2", r2)):
        for k, (a, b) in enumerate(zip(r["rss_time_mb"], r["rss_self_mb"], strict=False)):
            sp = r["setup_peak_mb"][k] if k < len(r["setup_peak_mb"]) else {}
            md.append(f"| {n} | {k} | {a:.0f} | {b:.0f} | {sp.get('mesh', 0):.0f} | {sp.get('assembly', 0):.0f} | "
                      f"{sp.get('factorisation', 0):.0f} | {sp.get('condensation', 0):.0f} |")
    m1, m2 = max(r1["rss_time_mb"]), max(r2["rss_time_mb"])
    md += ["", f"Largest rank at -n 2 / -n 1: {m2:.0f} / {m1:.0f} MB = **{m2 / m1:.2f}** (required ≤ {MEM_RATIO}).", "",
           "| ranks | set-up s | mesh | assembly + JIT | factorisation (MUMPS) | C (selected entries of K⁻¹) | per step (median) | whole run | MUMPS factor entries | MUMPS flops | MUMPS memory max rank / total MB |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for n, r in (("1", r1), ("2", r2)):
        st, mu = r["setup_times"], r["mumps"]
        md.append(f"| {n} | {r['setup_time']:.1f} | {st['mesh']:.1f} | {st['assembly']:.1f} | {st['factorisation']:.1f} | "
                  f"{st['condensation']:.1f} | {r['step_median']:.2f} | {r['wall']:.1f} | {mu.get('factor_entries', 0):.3g} | "
                  f"{mu.get('flops', 0):.3g} | {mu.get('mem_max_rank_mb')} / {mu.get('mem_total_mb')} |")
    ag = meas.get("agree_1_2")
    if ag:
        md += ["", f"-n 1 vs -n 2 on this case: du {ag['du']:.1e}, dE {ag['dE']:.1e}, dsig {ag['dsig']:.1e}, flags {ag['flags']}."]
    if meas.get("rust"):
        ru = meas["rust"]
        a = ru.get("agree_np2", {})
        md += [f"Rust binary on the same case: peak RSS {ru['rss_mb']:.0f} MB, {ru['wall']:.1f} s whole run; vs -n 2: "
               f"du {a.get('du', float('nan')):.1e}, dE {a.get('dE', float('nan')):.1e}, dsig {a.get('dsig', float('nan')):.1e}, "
               f"flags {a.get('flags')}."]
    md += ["", "Commands:", "", "```"] + meas["commands"] + ["```"]
    mo = meas.get("model")
    mu1, mu2 = r1["mumps"].get("mem_total_mb"), r2["mumps"].get("mem_max_rank_mb")
    if mo:
        md += ["", "## Scaling model (an estimate, not a measurement)", "",
               f"From the two measured points the largest rank's peak is m(P) = c + D/P with c = {mo['c_mb']:.0f} MB and "
               f"D = {mo['D_mb']:.0f} MB at n₀ = {mo['n0']:,} unknowns. D spreads over the ranks. Of c, b = {mo['b_mb']:.0f} MB "
               "is the import footprint (Python, dolfinx, PETSc, MPI; measured before the mesh exists). The rest, "
               f"{mo['c_mb'] - mo['b_mb']:.0f} MB, is what did not halve from 1 to 2 ranks: MUMPS' parallel overhead (by its "
               f"own count, INFOG(21/22): {mu1} MB at 1 rank, {mu2} MB on the largest rank at 2) and PETSc/dolfinx structures "
               "(ghosts, the PtAP product, the host's sequential METIS analysis of the whole graph). Two points cannot tell "
               "whether that part is a constant, grows with n on every rank, or falls with P; the column *per-rank peak* "
               "assumes the worst (∝ n on every rank), the column *if spread* the best (it spreads like D). "
               "(`--mumps-analysis parallel`, PT-Scotch, removes the host's analysis but gave a 10 % larger factor here.)", "",
               "Assumptions: structured 2D meshes with contact on one side, n_c ≈ √(n/6) contact edges; factor entries and "
               "solve work ∝ n log₂ n and factorisation flops ∝ n^1.5 (2D nested dissection); D grows like the factor and "
               "is split over P ranks with a load imbalance of 1.3; the non-spreading part grows ∝ n on every rank "
               "(pessimistic: column *per-rank peak*) or is removed (column *if spread*); times scale from the 1-rank "
               "measurement with parallel efficiency 0.5 (MUMPS across nodes, not measured here; this machine's times "
               "were taken under load and vary by ~1.5×); C is bounded by n_c solves (MUMPS prunes its tree for selected "
               "inverse entries, so it is cheaper); the dense C (n_c² doubles) and the friction step sit on rank 0, "
               "a dense active-set solve of O(n_c³) per iteration (n_c ≈ 4,100 at 10⁸ unknowns: ~7·10¹⁰ flop, seconds to "
               "tens of seconds per iteration) — beyond ~10⁸ unknowns the contact problem itself needs a distributed solver.", "",
               "| unknowns | ranks | n_c | per-rank peak GB | if spread GB | factorisation s | C s (bound) | per step s | C on rank 0 MB |",
               "|---|---|---|---|---|---|---|---|---|"]
        for r in mo["rows"]:
            md.append(f"| {r['n']:.0e} | {r['P']} | {r['nc']:.0f} | {r['mem_gb']:.1f} | {r['mem_spread_gb']:.1f} | "
                      f"{r['fact_s']:.0f} | {r['cond_s']:.0f} | {r['step_s']:.1f} | {r['C_mb']:.0f} |")
    return md

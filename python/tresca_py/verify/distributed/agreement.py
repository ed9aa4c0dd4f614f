"""D1: the distributed route against the Rust solver at -n 1, 2 and 3 on every cross-check scene (and a
Gmsh scene, once more with boundary data), and the requirement it makes."""
import os
import time

from tresca_py import compare
from tresca_py.common import case, cmdline
from tresca_py.common import short_path as rel
from tresca_py.verify import cross_check, routes  # scenes, quick levels; what the route models
from tresca_py.verify.distributed.runs import RANKS, TOL, dist_cmd, run
from tresca_py.verify.distributed.vtk_check import vtk_check


# the boundary-data scenes (issue 30 §1: dirichlet `u`, contact `gap`): D1 must cover them, so a filter that
# drops them from the case list fails D1 instead of passing it silently
DATA_CASES = ("mms_data_front", "mms_data_cep", "mms_data_stop")

GMSH_SCENE = ('title = "L-shape Gmsh mesh (verification/cases/lshape.msh) with Tresca contact on its floor '
              '(verification/distributed.py)"\n'
              """[mesh]
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
""")


def gmsh_data_scene(text):
    """GMSH_SCENE with Dirichlet data on the clamp and an imposed normal displacement on the floor, consistent
    at their common vertex (0, 0) (u·n = -u_y = gap) and with u0 = 0 at t0 = 0."""
    out = text.replace('kind = "dirichlet"\n', 'kind = "dirichlet"\nu = ["0.001*t*y", "0.002*t*(1+x)"]\n')
    out = out.replace('g_a = "0.001*(1+x)"', 'g_a = "0.001*(1+x)"\ngap = "-0.002*t*(1+x)"')
    out = out.replace('on its floor (verification/distributed.py)', 'on its floor, boundary data '
                                                                    '(verification/distributed.py)')
    assert out.count("gap =") == 1 and out.count("u = [") == 1, "GMSH_SCENE changed: update gmsh_data_scene"
    return out


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
        why = routes.unsupported("distributed", scenes[name])
        if why is not None:
            rows.append(outside(scenes[name], work, (name, tag, k, steps), why, commands))
            print(f"  [{'PASS' if row_ok(rows[-1]) else 'FAIL'}] {tag}: {fmt(rows[-1])}", flush=True)
            continue
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


def outside(scene, work, case_tag, why, commands):
    """The row of a scene the route does not model (``routes.scope``): run at -n 2, it must be refused naming the
    part (``routes.refused``)."""
    name, tag, k, steps = case_tag
    cmd = dist_cmd(scene, os.path.join(work, f"{tag}_dist_np2.h5"), k, steps, 2)
    p, wall = run(cmd)
    commands.append(cmdline(cmd))
    msg = (p.stderr or p.stdout).strip()[-300:]
    row = dict(case=name, refine=k, steps=steps, ranks=2, r=None, wall=wall)
    if routes.refused(p.returncode, msg, why[0]):
        return dict(row, outside=f"not supported by the distributed route: {why[1]}; refused with exit 2 naming it")
    return dict(row, err=f"the distributed route does not model {why[1]} but did not refuse it (exit "
                         f"{p.returncode}): {msg}")


def row_ok(row):
    r = row.get("r")
    if row.get("outside"):
        return True
    return r is not None and max(r["du"], r["dE"], r["dsig"], r["derr"]) <= TOL and r["flags"] == 0


def fmt(row):
    r = row.get("r")
    if r is None:
        return row.get("outside") or row.get("err") or "not comparable"
    s = f"du {r['du']:.1e}, dE {r['dE']:.1e}, dsig {r['dsig']:.1e}"
    if r["has_errors"]:
        s += f", derr {r['derr']:.1e}"
    return s + f", flags {r['flags']}"


def check_d1(hs, args, self_cmd):
    """D1: agreement with the Rust solver at -n 1, 2 and 3, and the VTK pieces read back; returns the rows
    and the commands."""
    t_start = time.perf_counter()
    print("D1: agreement with the Rust solver at -n 1, 2, 3", flush=True)
    rows, commands = agreement(args.bin, args.work)
    t_d1 = time.perf_counter() - t_start
    nfail = sum(not row_ok(r) for r in rows)
    worst = {
        k: max((r["r"][k] for r in rows if r.get("r")), default=float("nan")) for k in ("du", "dE", "dsig", "derr")
    }
    missing = [c for c in DATA_CASES if not any(r["case"] == c and r.get("r") for r in rows)]
    d1_ok = nfail == 0 and len(rows) > 0 and not missing
    n_out = sum(bool(r.get("outside")) for r in rows)
    d1_meas = (f"{len(rows) - nfail - n_out}/{len(rows) - n_out} runs agree, {n_out} scenes outside the route "
               f"refused; worst du {worst['du']:.1e}, dE {worst['dE']:.1e}, "
               f"dsig {worst['dsig']:.1e}, derr {worst['derr']:.1e}; {t_d1:.0f} s")
    if missing:
        d1_meas += f"; boundary-data scenes not run: {', '.join(missing)}"
    if nfail:
        d1_meas += (
            "; failing: " + "; ".join(f"{r['case']} -n {r['ranks']}: {fmt(r)}" for r in rows if not row_ok(r))[:400]
        )
    # the visualisation output of the last 3-rank run with contact (Example 5.1), read back with VTK
    vtk_h5 = next((r["file"] for r in rows if r["case"] == "paper_example_5_1" and r["ranks"] == 3 and r.get("file")),
                  None)
    vtk_ok, vtk_msg = vtk_check(vtk_h5) if vtk_h5 else (False, "no 3-rank run of paper_example_5_1")
    print(f"  [{'PASS' if vtk_ok else 'FAIL'}] VTK output: {vtk_msg}", flush=True)
    d1_ok = d1_ok and vtk_ok
    d1_meas += f"; VTK pieces of the -n 3 Example 5.1 run read back: {'ok' if vtk_ok else 'FAIL'} ({vtk_msg})"
    hs.require("D1-distributed-agree", d1_ok, d1_meas,
               statement=(f"the distributed dolfinx/PETSc route under mpirun -n 1, 2 and 3 shall agree with the Rust "
                          "solver on every cross-check scene (quick level; the boundary-data scenes "
                          f"{', '.join(DATA_CASES)} "
                          f"among them) within {TOL:g} relative in u, energy, σ_τ and "
                          f"true errors at every time node, with identical stick/slip sets; its parallel VTK output "
                          f"(discontinuous P1) shall read back in VTK with the CR values at every edge midpoint; a "
                          f"scene outside the route (tresca_py.verify.routes: unilateral, Coulomb, a load on Γ_C, a "
                          f"floating body) shall be refused naming the part"),
               command=self_cmd, reference="reference/distributed.md")
    return rows, commands

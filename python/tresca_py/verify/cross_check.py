"""Cross-check of the three independent solvers of tresca-cr (issue 6): Rust, scikit-fem, dolfinx.

    .venv/bin/python verification/cross_check.py [--quick] [--no-mpi] [--json out/cross_check.json]
                                                 [--md reference/cross_check.md] [--only CASE ...]

For every scene of verification/cases/*.toml (plus generated scenes that exercise expression semantics)
at two mesh levels, it runs

    target/release/tresca-cr run SCENE -o rs.h5 --force -q --refine k [--steps N]
    .venv/bin/python scripts/skfem_solve.py   SCENE -o sk.h5 -q --refine k [--steps N]
    .venv/bin/python scripts/dolfinx_solve.py SCENE -o dx.h5 -q --refine k [--steps N]

one after the other (so the wall times are comparable), and compares every pair with scripts/compare.py:
at every time node the relative difference of the CR DOF vectors, of the energies a_h(u,u), the
difference of the tangential tractions relative to max ḡ, the relative difference of the true errors
(energy, H1, L2; when the scene has [exact]) -- all required <= 1e-8 -- and the stick/slip sets, required
identical.  dolfinx under `mpirun -n 2` is compared with serial dolfinx on contact cases.

Writes a requirement list (JSON, merged by verification/run_all.py) and a Markdown report (table, commands,
versions; reference/cross_check.md for the full run, out/cross_check_quick.md for --quick), prints the
table and exits 1 if any requirement fails.
"""
import argparse
import importlib.metadata
import os
import platform
import subprocess
import sys
import time

import h5py
import numpy as np

from tresca_py.common import BIN, MPIRUN, PY, ROOT  # noqa: E402
from tresca_py.common import CASES as CASES_DIR  # noqa: E402
from tresca_py.common import cmdline  # noqa: E402
from tresca_py.common import short_path as rel  # noqa: E402

from tresca_py import compare  # noqa: E402
from tresca_py.verify.harness import Harness, out_dir  # noqa: E402

TOL = 1e-8

# case -> (levels, steps override or None) ; quick: one level each
FULL = {
    "mms_front": ((0, 1), 16),
    "mms_rotated": ((0, 1), None),
    "mms_stop": ((1, 2), None),
    "mms_elastic": ((1, 2), None),
    "mms_stick_to_slip": ((1, 2), None),
    "paper_example_5_1": ((1, 2), None),
    "pdas_cycle": ((0, 1), None),
    "expr_signum": ((0, 1), 8),
    "expr_functions": ((0, 1), 8),
}
QUICK = {
    "mms_front": ((0,), 8),
    "mms_rotated": ((0,), None),
    "mms_stop": ((1,), None),
    "mms_elastic": ((0,), None),
    "mms_stick_to_slip": ((0,), None),
    "paper_example_5_1": ((1,), 20),
    "pdas_cycle": ((0,), None),
    "expr_signum": ((0,), 4),
    "expr_functions": ((0,), 4),
}
# dolfinx mpirun -n 2 versus serial (case, refine)
MPI_FULL = [("paper_example_5_1", 2), ("mms_front", 1), ("mms_data_stop", 1)]
MPI_QUICK = [("pdas_cycle", 0)]

PAIRS = (("rust", "skfem"), ("rust", "dolfinx"), ("skfem", "dolfinx"))

NOTES = """## Notes

**What the three codes share.** They read the same scene expressions the same way and classify contact
edges by the same rule, so identical numbers and identical stick/slip sets can be required:

1. `signum(0) = +1` everywhere: Rust evaluates `f64::signum`; the Python reader (tresca_py/expr.py) writes
   `signum` as a Piecewise with value +1 at 0, which the dolfinx solvers translate to `ufl.conditional`.
2. Stick/slip: an edge slips at step n when |Δs_e| > 1e-9 max(|Δs|, |d|), in Rust (`friction::classify`) and
   in Python (`tresca_py.skfem_cr.friction.classify`, used by both Python solvers).
3. Constants: `PI`, `π`, `E`, `e`, `TAU`, `τ`, and lower-case `pi` read as `PI` by both readers
   (src/scene/expr/lint.rs, tresca_py/expr.py).

**Rounding amplification of derr.** |e_A - e_B| <= |||u_A - u_B||| (reverse triangle inequality), so the
relative difference of the true errors is up to du·|||u|||/e: the DOF vectors agree to about κ(a_h)·eps
(du grows about 5x per refinement: 3e-14, 2e-13, 1.3e-12, 6e-12, 3e-11 on mms_elastic refine 0..4), and
the L2 error shrinks 4x, so derr grows about 20x per refinement (3e-13, 7e-12, 2e-10, 4e-9, 7e-8 on
mms_elastic). The 1e-8 bound on derr therefore holds up to refine 3 only; the levels used here stay at
or below refine 2. Beyond that a bound on |e_A - e_B| / |||u||| is the meaningful one.

**Near incompressibility.** near_incompressible (ν = 0.4999) agrees to 1e-11, but with ν = 0.4999999
(E = 2(1+ν)) κ(a_h)·eps reaches about 1e-7: Rust differs from both Python codes by du 2e-8 (refine 1) and
1e-7 (refine 2), skfem from dolfinx by 2e-9 and 2e-8. Against a skfem solve with 5 steps of iterative
refinement the errors at refine 2 are: Rust 1.1e-7, dolfinx 1.8e-8, skfem (1 refinement step) 1.6e-9,
skfem without refinement 1.8e-8. The Python solvers do one step of iterative refinement after SuperLU;
the Rust solver (src/solve/cholesky/factor.rs, `Factor::solve_in_place` / `solve_many`) does none. A 1e-8
agreement is not a meaningful requirement there (assembly rounding alone moves dolfinx 1.8e-8 from skfem).

**Wall times.** The Python processes spend 1.5–3 s in start-up (imports; dolfinx form compilation on
first use, cached afterwards), so on these small meshes the whole-process times compare start-up costs;
the bracketed in-process times compare the solvers.
"""


def generated_scenes(workdir):
    """Scenes written here: expression semantics the three codes must read alike.

    expr_functions: Example 5.1 with every function and constant of the scene syntax that both readers know.
    expr_signum: Example 5.1 with exmex's signum(0) = 1 (Rust f64::signum) in the friction bound, the
    traction (UFL path of dolfinx) and the body force; sympy's sign(0) = 0 made the Python solvers differ.
    """
    with open(os.path.join(CASES_DIR, "paper_example_5_1.toml")) as fh:
        text = fh.read()
    text = text.replace('traction = ["0.02*(5-y)*t", "-0.01*t"]',
                        'traction = ["0.01*(5-y)*t*(1 + signum(0*y))", "-0.01*t*signum(y - 2)"]')
    text = text.replace('g_a = "0.0012"', 'g_a = "0.0012*(1 + signum(0*x)) + 0.0006*signum(x - 2)"')
    text = text.replace("[discretisation]", '[loads]\nf = ["0.001*signum(x - y)", "0"]\n\n[discretisation]')
    assert text.count("signum") == 5, "paper_example_5_1.toml changed; update generated_scenes()"
    text = text.replace('title = "Porwal & Wadhawan, Example 5.1"',
                        'title = "Example 5.1 with signum(0) in g_a, traction and f (generated by '
                        'verification/cross_check.py)"')
    out = {"expr_signum": os.path.join(workdir, "expr_signum.toml")}
    with open(out["expr_signum"], "w") as fh:
        fh.write(text)
    # every function and constant both readers know, scientific notation (1e-3, 2.5E-3) next to the constant e
    with open(os.path.join(CASES_DIR, "paper_example_5_1.toml")) as fh:
        text = fh.read()
    text = text.replace('traction = ["0.02*(5-y)*t", "-0.01*t"]',
                        'traction = ["0.02*(5-y)*t + 1e-3*PI*e^(-y) - 2.5E-3*E*t", '
                        '"-0.01*t*(1 + 0.1*sin(PI*y/4)^2) + 2e-3*t*cosh(0.1*y)/sinh(1+0.1*y)"]')
    text = text.replace('g_a = "0.0012"',
                        'g_a = "0.0006*(2 + sin(x)*cos(x) + tan(0.1*x) + exp(-x) + ln(1+x) + log(2+x) + sqrt(1+x) '
                        '+ abs(x-1.3) + tanh(x-2) + sinh(0.1*x) + cosh(0.1*x) + atan2(x-1, 2) + min(x, 1.5) '
                        '+ max(x, 2.5) + floor(x) + signum(x-1.7))/3"')
    text = text.replace("[discretisation]", '[loads]\nf = ["0.01*tanh(x-y)*max(t, 0.5) + 0.001*atan2(y, x+1)", '
                        '"0.01*abs(x-2)^1.5*t - 0.002*min(y, 2)*exp(-t)"]\n\n[discretisation]')
    assert text.count("atan2") == 2, "paper_example_5_1.toml changed; update generated_scenes()"
    text = text.replace('title = "Porwal & Wadhawan, Example 5.1"',
                        'title = "Example 5.1 with every expression function in g_a, traction and f '
                        '(generated by verification/cross_check.py)"')
    out["expr_functions"] = os.path.join(workdir, "expr_functions.toml")
    with open(out["expr_functions"], "w") as fh:
        fh.write(text)
    return out


def run_code(code, scene, out, refine, steps, mpi=0):
    """Run one solver; returns (ok, wall seconds, command string, message)."""
    extra = ["--refine", str(refine)] + (["--steps", str(steps)] if steps else [])
    if code == "rust":
        cmd = [BIN, "run", scene, "-o", out, "--force", "-q"] + extra
    else:
        cmd = ([MPIRUN, "-n", str(mpi)] if mpi else []) + \
              [PY, os.path.join(ROOT, "scripts", f"{code}_solve.py"), scene, "-o", out, "-q", "--force"] + extra
    if os.path.exists(out) and code != "rust":
        os.remove(out)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    msg = "" if p.returncode == 0 else (p.stderr.strip() or p.stdout.strip())[-400:]
    return p.returncode == 0, wall, cmdline(cmd), msg


def inner_time(path, code):
    """Time spent inside the solver as recorded in the results file (set-up + steps), or None."""
    try:
        with h5py.File(path, "r") as fh:
            g = fh["tresca"]
            if code == "rust":
                return float(np.sum(g.attrs["setup_times"]) + np.sum(g["steps/wall_time"][()]))
            return float(g.attrs["total_time"])
    except Exception:  # noqa: BLE001
        return None


def sizes(path):
    with h5py.File(path, "r") as fh:
        g = fh["tresca"]
        nc = int(g["contact/edges"].shape[0]) if "contact/edges" in g else 0
        return int(g["mesh/edges"].shape[0]), nc, int(g["times"].shape[0] - 1)


def compare_pair(a, b):
    try:
        r = compare.compare_files(a, b)
    except compare.CompareError as err:
        return None, str(err)
    return r, None


def pair_ok(r):
    return r is not None and max(r["du"], r["dE"], r["dsig"], r["derr"]) <= TOL and r["flags"] == 0


def fmt_pair(r):
    if r is None:
        return "not comparable"
    s = f"du {r['du']:.1e}, dE {r['dE']:.1e}, dsig {r['dsig']:.1e}"
    if r["has_errors"]:
        s += f", derr {r['derr']:.1e}"
    return s + f", flags {r['flags']}"


def versions():
    v = {}
    try:
        v["tresca-cr"] = subprocess.run([BIN, "--version"], capture_output=True, text=True).stdout.strip()
    except OSError:
        v["tresca-cr"] = "missing"
    try:
        v["rustc"] = subprocess.run(["rustc", "--version"], capture_output=True, text=True).stdout.strip()
    except OSError:
        v["rustc"] = "?"
    v["python"] = platform.python_version()
    for p in ("numpy", "scipy", "scikit-fem", "dolfinx-solver-real", "fenics-basix", "fenics-ffcx", "fenics-ufl",
              "mpi4py", "mpich", "h5py", "sympy", "meshio"):
        try:
            v[p] = importlib.metadata.version(p)
        except importlib.metadata.PackageNotFoundError:
            pass
    try:
        v["git"] = subprocess.run(["git", "rev-parse", "--short=12", "HEAD"], cwd=ROOT, capture_output=True,
                                  text=True).stdout.strip()
    except OSError:
        pass
    v["machine"] = f"{platform.machine()}, {os.cpu_count()} cores, {platform.platform()}"
    return v


class Context:
    """What the checks of one cross-check share: the harness, the work directory, the scenes, and the rows,
    timings and commands the report lists."""

    def __init__(self, hs, work, scenes, self_cmd, md_path):
        self.hs, self.work, self.scenes, self.self_cmd, self.md_path = hs, work, scenes, self_cmd, md_path
        self.rows, self.timing, self.commands = [], [], []


def check_case(cx, name, k, steps):
    """Rust, scikit-fem and dolfinx on one case at refine k: the three pairs compared, one requirement."""
    tag = f"{name}_r{k}" + (f"_n{steps}" if steps else "")
    files, walls, inner, errs = {}, {}, {}, []
    for code in ("rust", "skfem", "dolfinx"):
        out = os.path.join(cx.work, f"{tag}_{code}.h5")
        ok, wall, cmd, msg = run_code(code, cx.scenes[name], out, k, steps)
        cx.commands.append(cmd)
        walls[code] = wall
        if ok:
            files[code] = out
            inner[code] = inner_time(out, code)
        else:
            errs.append(f"{code} failed: {msg}")
            print(f"  {code} FAILED on {tag}: {msg}", flush=True)
    n_edges = n_contact = n_steps = None
    if files:
        n_edges, n_contact, n_steps = sizes(next(iter(files.values())))
    results = {}
    for a, b in PAIRS:
        if a in files and b in files:
            r, err = compare_pair(files[a], files[b])
            results[(a, b)] = r
            if err:
                errs.append(f"{a} vs {b}: {err}")
            cx.rows.append(dict(case=name, refine=k, steps=n_steps, pair=f"{a}–{b}", r=r))
            cx.commands.append(f".venv/bin/python scripts/compare.py {rel(files[a])} {rel(files[b])} --strict-flags")
    passed = not errs and len(results) == 3 and all(pair_ok(r) for r in results.values())
    measured = "; ".join(f"{a}–{b}: {fmt_pair(results.get((a, b)))}" for a, b in PAIRS if (a, b) in results)
    if errs:
        measured = "; ".join(errs) + ("; " + measured if measured else "")
    cx.timing.append(dict(case=name, refine=k, steps=n_steps, edges=n_edges, contact=n_contact,
                          wall=walls, inner=inner))
    cx.hs.require(f"X-{name}-r{k}", passed, measured,
                  statement=(f"Rust, scikit-fem and dolfinx shall agree on {name} at refine {k}"
                             f"{f' ({steps} steps)' if steps else ''}: DOF vectors, energies, σ_τ"
                             f"{', true errors' if any(r and r['has_errors'] for r in results.values()) else ''}"
                             f" within {TOL:g} (relative) at every time node, identical stick/slip sets"),
                  command=f"{cx.self_cmd} --only {name}", reference=rel(cx.md_path))


def check_mpi(cx, name, k, plan):
    """dolfinx under mpirun -n 2 against serial dolfinx on one case at refine k; returns its table row."""
    steps = plan.get(name, ((), None))[1]
    tag = f"{name}_r{k}" + (f"_n{steps}" if steps else "")
    serial = os.path.join(cx.work, f"{tag}_dolfinx.h5")
    errs = []
    if not os.path.exists(serial) or k not in plan.get(name, ((),))[0]:
        ok, wall, cmd, msg = run_code("dolfinx", cx.scenes[name], serial, k, steps)
        cx.commands.append(cmd)
        if not ok:
            errs.append(f"serial dolfinx failed: {msg}")
    par = os.path.join(cx.work, f"{tag}_dolfinx_np2.h5")
    ok, wall, cmd, msg = run_code("dolfinx", cx.scenes[name], par, k, steps, mpi=2)
    cx.commands.append(cmd)
    r = None
    if not ok:
        errs.append(f"mpirun -n 2 dolfinx failed: {msg}")
    elif not errs:
        r, err = compare_pair(serial, par)
        if err:
            errs.append(err)
        cx.commands.append(f".venv/bin/python scripts/compare.py {rel(serial)} {rel(par)} --strict-flags")
    passed = not errs and pair_ok(r)
    measured = "; ".join(errs) if errs else fmt_pair(r)
    for t in cx.timing:
        if t["case"] == name and t["refine"] == k:
            t["wall"]["dolfinx -n 2"] = wall
            t["inner"]["dolfinx -n 2"] = inner_time(par, "dolfinx") if ok else None
    cx.hs.require(f"X-mpi-{name}-r{k}", passed, measured,
                  statement=(f"dolfinx under mpirun -n 2 shall agree with serial dolfinx on {name} at refine {k} "
                             f"within {TOL:g} (DOFs, energies, σ_τ, true errors) with identical stick/slip sets"),
                  command=f"{cx.self_cmd} --only {name}", reference=rel(cx.md_path))
    return dict(case=name, refine=k, steps=steps, r=r, wall=wall, passed=passed, measured=measured)


def tables(cx, mpi_rows):
    """The agreement and wall-time tables (Markdown)."""
    codes = ["rust", "skfem", "dolfinx"] + (["dolfinx -n 2"] if mpi_rows else [])
    lines = [
        "Agreement (max over the time nodes; du, dE, derr relative; dsig relative to max ḡ; flags = differing "
        "stick/slip states summed over the nodes):",
        "",
        "| case | refine | N | pair | du | dE | dsig | derr | flags | ok |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in cx.rows:
        r = row["r"]
        if r is None:
            lines.append("| "
                         f"{row['case']} | "
                         f"{row['refine']} | {row['steps']} | {row['pair']} | – | – | – | – | – | FAIL |")
            continue
        derr = f"{r['derr']:.1e}" if r["has_errors"] else "–"
        lines.append("| "
                     f"{row['case']} | "
                     f"{row['refine']} | {row['steps']} | {row['pair']} | {r['du']:.1e} | {r['dE']:.1e} | "
                     f"{r['dsig']:.1e} | {derr} | {r['flags']} | {'PASS' if pair_ok(r) else 'FAIL'} |")
    for m in mpi_rows:
        r = m["r"]
        if r is None:
            lines.append(f"| {m['case']} | {m['refine']} | – | dolfinx–dolfinx -n 2 | – | – | – | – | – | FAIL |")
            continue
        derr = f"{r['derr']:.1e}" if r["has_errors"] else "–"
        lines.append(f"| {m['case']} | {m['refine']} | {r['n_times'] - 1} | dolfinx–dolfinx -n 2 | {r['du']:.1e} | "
                     f"{r['dE']:.1e} | {r['dsig']:.1e} | {derr} | {r['flags']} | {'PASS' if m['passed'] else 'FAIL'} |")
    lines += [
        "",
        "Wall time in seconds: whole process (start-up, scene, assembly, every step, true errors, output), "
        "in brackets the solver's own record (Rust: set-up + steps, without true errors and output; Python: "
        "assembly + steps + true errors, after imports and scene loading).",
        "",
        "| case | refine | N | edges | Γ_C edges | " + " | ".join(codes) + " |",
        "|---|---|---|---|---|" + "---|" * len(codes),
    ]
    for t in cx.timing:
        cells = []
        for c in codes:
            if c in t["wall"]:
                inn = t["inner"].get(c)
                cells.append(f"{t['wall'][c]:.2f}" + (f" ({inn:.3f})" if inn is not None else ""))
            else:
                cells.append("–")
        lines.append(
            f"| {t['case']} | {t['refine']} | {t['steps']} | {t['edges']} | {t['contact']} | "
            + " | ".join(cells)
            + " |"
        )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one mesh level per case, fewer steps (make test)")
    ap.add_argument("--no-mpi", action="store_true", help="skip dolfinx under mpirun -n 2")
    ap.add_argument("--json", default=os.path.join(ROOT, "out", "cross_check.json"), help="requirement list")
    ap.add_argument("--md", default=None, help="Markdown report (default reference/cross_check.md, "
                    "out/cross_check_quick.md with --quick)")
    ap.add_argument("--work", default=None, help="directory for the results files (default out/cross_check[_quick])")
    ap.add_argument("--only", nargs="+", metavar="CASE", help="only these cases")
    args = ap.parse_args(argv)
    t_start = time.perf_counter()
    plan = dict(QUICK if args.quick else FULL)
    mpi_plan = [] if args.no_mpi else list(MPI_QUICK if args.quick else MPI_FULL)
    on_disk = sorted(f[:-5] for f in os.listdir(CASES_DIR) if f.endswith(".toml"))
    for name in on_disk:                    # a new case file is cross-checked without editing this script
        plan.setdefault(name, ((0,), None) if args.quick else ((0, 1), None))
    if args.only:
        unknown = set(args.only) - set(plan)
        if unknown:
            sys.exit(f"error: unknown case(s) {sorted(unknown)} (known: {sorted(plan)})")
        plan = {k: v for k, v in plan.items() if k in args.only}
        mpi_plan = [m for m in mpi_plan if m[0] in args.only]
    suffix = "_quick" if args.quick else ""
    work = args.work or os.path.join(ROOT, "out", f"cross_check{suffix}")
    md_path = args.md or (os.path.join(ROOT, "out", "cross_check_quick.md") if args.quick
                          else os.path.join(ROOT, "reference", "cross_check.md"))
    os.makedirs(work, exist_ok=True)
    scenes = {n: os.path.join(CASES_DIR, f"{n}.toml") for n in on_disk}
    scenes.update(generated_scenes(work))
    if not os.path.exists(BIN):
        sys.exit(f"error: {rel(BIN)} missing (cargo build --release)")

    hs = Harness(out=os.path.join(out_dir(), "cross_check_harness"))
    self_cmd = f".venv/bin/python verification/cross_check.py{' --quick' if args.quick else ''}"
    cx = Context(hs, work, scenes, self_cmd, md_path)
    for name, (levels, steps) in plan.items():
        for k in levels:
            check_case(cx, name, k, steps)
    mpi_rows = [check_mpi(cx, name, k, plan) for name, k in mpi_plan]
    total = time.perf_counter() - t_start
    table = tables(cx, mpi_rows)
    print("\n" + table)
    reqs, nfail = hs.results, len(hs.failed)
    print(f"\n{len(reqs) - nfail}/{len(reqs)} cross-check requirements passed in {total:.0f} s")

    ver = versions()
    md = [f"<!-- generated by verification/cross_check.py{' --quick' if args.quick else ''} -->",
          "# Cross-check: Rust, scikit-fem and dolfinx (issue 6)", "",
          f"`{self_cmd}{' --no-mpi' if args.no_mpi else ''}` — {len(reqs) - nfail}/{len(reqs)} requirements passed, "
          f"{total:.0f} s in all. Tolerance {TOL:g}; stick/slip sets must be identical.", "",
          "Stick/slip convention of all three codes (Rust `friction::classify`): an edge slips at step n when "
          "|μ_e| ≥ w_e(1 − 1e-9) and |Δs_e| > 1e-9·max(‖Δs‖∞, ‖d‖∞), Δs = d − Cμ the slip increment, d the "
          "increment without friction; state 0 and μ = 0 at step 0; σ_τ = −μ/|e|; exmex's signum(0) = 1.", "",
          "## Requirements", "", "| id | passed | measured |", "|---|---|---|"]
    md += [f"| {r.id} | {'PASS' if r.passed else 'FAIL'} | {r.measured} |" for r in reqs]
    md += [
        "",
        "## Tables",
        "",
        table,
        "",
        "## Commands",
        "",
        "Run from the repository root, one after the other:",
        "",
        "```",
    ]
    md += cx.commands
    md += ["```", "", NOTES, "## Versions", ""] + [f"- {k}: {v}" for k, v in ver.items()] + [""]
    os.makedirs(os.path.dirname(md_path), exist_ok=True)
    with open(md_path, "w") as fh:
        fh.write("\n".join(md))
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    hs.dump(args.json)
    print(f"wrote {rel(md_path)} and {rel(os.path.abspath(args.json))}")
    return 1 if nfail else 0

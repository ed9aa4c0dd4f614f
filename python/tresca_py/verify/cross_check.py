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
import os
import sys
import time

from tresca_py.common import BIN, ROOT
from tresca_py.common import CASES as CASES_DIR
from tresca_py.common import short_path as rel
from tresca_py.verify import routes
from tresca_py.verify.cross_report import tables, write_markdown
from tresca_py.verify.cross_runs import TOL, compare_pair, fmt_pair, inner_time, pair_ok, run_code, run_route, sizes
from tresca_py.verify.cross_scenes import generated_scenes
from tresca_py.verify.harness import Harness, out_dir

# the names other modules read here: the cases directory, the quick plan, the scenes written, the runs
__all__ = ("CASES_DIR", "FULL", "QUICK", "TOL", "compare_pair", "fmt_pair", "generated_scenes", "main", "run_code")

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

CODES = ("rust", "skfem", "dolfinx")
PAIRS = (("rust", "skfem"), ("rust", "dolfinx"), ("skfem", "dolfinx"))

class Context:
    """What the checks of one cross-check share: the harness, the work directory, the scenes, and the rows,
    timings and commands the report lists."""

    def __init__(self, hs, work, scenes, self_cmd, md_path):
        self.hs, self.work, self.scenes, self.self_cmd, self.md_path = hs, work, scenes, self_cmd, md_path
        self.rows, self.timing, self.commands = [], [], []


def run_one(cx, code, name, tag, k, steps):
    """Run ``code`` on case ``name``; returns (file or None, wall, error or None, outside or None). A route that
    does not model the scene (``routes.scope``) must refuse it with a message naming the part: outside is then
    "not supported by <code>: <why>", and a run that is not such a refusal is an error."""
    out = os.path.join(cx.work, f"{tag}_{code}.h5")
    rc, wall, cmd, msg = run_route(code, cx.scenes[name], out, k, steps)
    cx.commands.append(cmd)
    why = None if code == "rust" else routes.unsupported(code, cx.scenes[name])
    if why is not None:
        if routes.refused(rc, msg, why[0]):
            return None, wall, None, f"not supported by {code}: {why[1]}; refused with exit 2 naming it"
        return None, wall, f"{code} does not model {why[1]} but did not refuse it (exit {rc}): {msg}", None
    if rc != 0:
        print(f"  {code} FAILED on {tag}: {msg}", flush=True)
        return None, wall, f"{code} failed: {msg}", None
    return out, wall, None, None


def check_case(cx, name, k, steps):
    """Rust, scikit-fem and dolfinx on one case at refine k: the pairs of the codes that model it compared, the
    others shown refusing it (``routes``), one requirement."""
    tag = f"{name}_r{k}" + (f"_n{steps}" if steps else "")
    files, walls, inner, errs, outside = {}, {}, {}, [], {}
    for code in CODES:
        out, walls[code], err, why = run_one(cx, code, name, tag, k, steps)
        if out:
            files[code], inner[code] = out, inner_time(out, code)
        errs += [err] if err else []
        if why:
            outside[code] = why
    n_edges = n_contact = n_steps = None
    if files:
        n_edges, n_contact, n_steps = sizes(next(iter(files.values())))
    results = {}
    for a, b in PAIRS:
        if a in outside or b in outside:
            cx.rows.append(dict(case=name, refine=k, steps=n_steps, pair=f"{a}–{b}", r=None,
                                outside=outside.get(b, outside.get(a))))
        elif a in files and b in files:
            r, err = compare_pair(files[a], files[b])
            results[(a, b)] = r
            if err:
                errs.append(f"{a} vs {b}: {err}")
            cx.rows.append(dict(case=name, refine=k, steps=n_steps, pair=f"{a}–{b}", r=r))
            cx.commands.append(f".venv/bin/python scripts/compare.py {rel(files[a])} {rel(files[b])} --strict-flags")
    compared = [(a, b) for a, b in PAIRS if a not in outside and b not in outside]
    passed = (not errs and len(compared) >= 1 and len(results) == len(compared)
              and all(pair_ok(r) for r in results.values()))
    measured = "; ".join(f"{a}–{b}: {fmt_pair(results.get((a, b)))}" for a, b in PAIRS if (a, b) in results)
    measured = "; ".join(errs + ([measured] if measured else []) + list(outside.values()))
    cx.timing.append(dict(case=name, refine=k, steps=n_steps, edges=n_edges, contact=n_contact,
                          wall=walls, inner=inner))
    codes = [c for c in CODES if c not in outside]
    who = ", ".join(codes[:-1]) + " and " + codes[-1] if len(codes) > 1 else codes[0]
    cx.hs.require(f"X-{name}-r{k}", passed, measured,
                  statement=(f"{who.replace('rust', 'Rust').replace('skfem', 'scikit-fem')} shall agree on {name} "
                             f"at refine {k}{f' ({steps} steps)' if steps else ''}: DOF vectors, energies, σ_τ"
                             f"{', true errors' if any(r and r['has_errors'] for r in results.values()) else ''}"
                             f" within {TOL:g} (relative) at every time node, identical stick/slip sets"
                             + "".join(f"; {c}, which does not model it, shall refuse it naming the part"
                                       for c in outside)),
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

    write_markdown(cx, args, table, total)
    os.makedirs(os.path.dirname(os.path.abspath(args.json)), exist_ok=True)
    hs.dump(args.json)
    print(f"wrote {rel(md_path)} and {rel(os.path.abspath(args.json))}")
    return 1 if nfail else 0

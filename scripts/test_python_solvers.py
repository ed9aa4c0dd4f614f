"""Checks of the independent Python solvers (scikit-fem and dolfinx) of tresca-cr.

Usage:  python scripts/test_python_solvers.py [--quick] [--no-mpi] [--no-cases] [--write-scenes DIR]

Plain script (no pytest needed); prints one line per check and exits non-zero if any fails.

1. expression translation (exmex syntax -> sympy/numpy) and clear errors on bad input;
2. meshes: structured counts/orientation/side names, refine = 2^k cells, red refinement of Gmsh meshes;
3. the exact dual box-QP solver against its KKT conditions on random problems (incl. w_e = 0);
4. affine patch tests (skewed quadrilateral, both diagonals; with frictionless contact): the discrete
   solution is the CR interpolant of the affine field, so every true error vanishes (to rounding);
5. skfem and dolfinx agree to 1e-8 (DOFs, energies, tractions, true errors) on a plain-elasticity
   manufactured solution and on contact scenes (Example 5.1, cyclic stick/slip, Gmsh trapezoid);
6. dolfinx under ``mpirun -n 2`` agrees with serial dolfinx to 1e-8;
7. every stored step satisfies the discrete variational inequality: K_r r = P^T l - B mu,
   |mu_e| <= w_e, mu_e = w_e sign(ds_e) where ds_e != 0 (checked from the results file alone);
8. manufactured elasticity: energy error O(h), L2 error O(h^2);
9. bad scenes fail with a one-line ``error:`` message;
10. if present: skfem == dolfinx on verification/cases/*.toml, and skfem == Rust (target/release/tresca-cr
    run SCENE -o OUT) on the scenes above.
The scenes of 4 and 8 are generated here with sympy (f = -div sigma(u), g = sigma(u) n).
"""
import argparse
import atexit
import os
import shutil
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "verification"))
from tresca_py import tresca_scene as ts  # noqa: E402
from tresca_py.common import CASES, MPIRUN, PY  # noqa: E402
from tresca_py.common import run as run_cmd  # noqa: E402

RESULTS = []


def check(name, ok, detail=""):
    RESULTS.append((name, bool(ok)))
    print(f"[{'PASS' if ok else 'FAIL'}] {name}" + (f": {detail}" if detail else ""), flush=True)
    return ok


def run(cmd, expect_ok=True):
    return run_cmd(cmd, check=expect_ok)[0]


def solve(solver, scene, out, extra=(), mpi=0):
    script = os.path.join(HERE, f"{solver}_solve.py")
    cmd = ([MPIRUN, "-n", str(mpi)] if mpi else []) + [PY, script, scene, "-o", out, "-q", *extra]
    return run_cmd(cmd)[1]


def compare(a, b, tol=1e-8):
    p = run([PY, os.path.join(HERE, "compare.py"), a, b, "--tol", str(tol), "--quiet"], expect_ok=False)
    return p.returncode == 0, p.stdout.strip().splitlines()[-1] if p.stdout.strip() else p.stderr.strip()


# ----------------------------------------------------------------------------------------------
# scene generation (sympy)
# ----------------------------------------------------------------------------------------------
def exmex(expr):
    """Print a sympy expression in exmex syntax; powers fully parenthesised ((a)^(b))."""
    import sympy
    from sympy.printing.str import StrPrinter

    class P(StrPrinter):
        def _print_Pow(self, e, rational=False):
            b, x = e.args
            if x == sympy.Rational(1, 2):
                return f"sqrt({self._print(b)})"
            if x == -1:
                return f"(1/({self._print(b)}))"
            return f"(({self._print(b)})^({self._print(x)}))"

        def _print_Exp1(self, e):
            return "E"

        def _print_Pi(self, e):
            return "PI"

    return P().doprint(expr)


def mms_scene(u_expr, corners, cells, sides, E=100.0, nu=0.3, diagonal="first", times=(0.0, 0.5, 1.0),
              g_a=None, title="manufactured", u0=True):
    """Scene text for the exact field u (sympy 2-vector in x, y, t).

    ``sides``: dict side -> kind ("dirichlet" | "neumann" | "contact"); Neumann tractions are sigma(u) n,
    the body force is -div sigma(u).
    """
    import sympy
    x, y, t = sympy.symbols("x y t", real=True)
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    u = sympy.Matrix(u_expr)
    G = u.jacobian([x, y])
    eps = (G + G.T) / 2
    sig = lam * eps.trace() * sympy.eye(2) + 2 * mu * eps
    f = -sympy.Matrix([sympy.diff(sig[0, 0], x) + sympy.diff(sig[0, 1], y),
                       sympy.diff(sig[1, 0], x) + sympy.diff(sig[1, 1], y)])
    f = f.applyfunc(sympy.simplify)
    c = [np.asarray(p, float) for p in corners]
    side_pts = {"bottom": (0, 1), "right": (1, 2), "top": (2, 3), "left": (3, 0)}
    q = lambda v: "[" + ", ".join(f'"{exmex(sympy.nsimplify(a) if a.is_number else a)}"' for a in v) + "]"  # noqa: E731
    lines = [f'title = "{title}"', "", "[mesh]",
             f"corners = {[list(map(float, p)) for p in corners]}", f"cells = {list(cells)}",
             f'diagonal = "{diagonal}"', "", "[material]", f"E = {E}", f"nu = {nu}", ""]
    for side, kind in sides.items():
        lines += ["[[boundary]]", f'name = "{side}"', f'kind = "{kind}"']
        if kind == "neumann":
            a, b = side_pts[side]
            d = c[b] - c[a]
            n = sympy.Matrix([sympy.nsimplify(d[1]), sympy.nsimplify(-d[0])])
            n = n / sympy.sqrt(n.dot(n))
            g = (sig * n).applyfunc(sympy.simplify)
            lines.append(f"traction = {q(g)}")
        if kind == "contact":
            lines.append(f'g_a = "{g_a}"')
        lines.append("")
    if any(v != 0 for v in f):
        lines += ["[loads]", f"f = {q(f)}", ""]
    if u0:
        lines += ["[initial]", f"u0 = {q(u.subs(t, times[0]))}", ""]
    lines += ["[time]", f"times = {list(map(float, times))}", "", "[discretisation]", "rho = 10.0", "",
              "[exact]", f"u = {q(u)}",
              "grad = [" + ", ".join(q(G.row(i)) for i in range(2)) + "]", ""]
    return "\n".join(lines)


def generated_scenes():
    import sympy
    x, y, t = sympy.symbols("x y t", real=True)
    R = sympy.Rational
    scenes = {}
    # affine field vanishing on the (skewed) right side c1-c2
    corners = [[0.0, 0.0], [3.0, 0.5], [3.5, 2.5], [0.5, 2.0]]
    ell = R(1, 2) * (y - R(1, 2)) - 2 * (x - 3)
    s = R(1, 2) + t
    u = [s * ell * R(1, 1000), -s * ell * R(2, 1000)]
    for diag in ("first", "second"):
        scenes[f"patch_elastic_{diag}"] = mms_scene(
            u, corners, (5, 4), {"right": "dirichlet", "bottom": "neumann", "top": "neumann", "left": "neumann"},
            diagonal=diag, title=f"affine patch test ({diag} diagonal)")
    # frictionless contact patch test: u = s(t) (a (x-3), 0) on a block with vertical right side
    corners_c = [[0.0, 0.0], [3.0, 0.0], [3.0, 2.5], [0.4, 2.0]]
    u_c = [s * (x - 3) * R(1, 1000), sympy.Integer(0)]
    scenes["patch_contact"] = mms_scene(
        u_c, corners_c, (6, 5), {"right": "dirichlet", "bottom": "contact", "top": "neumann", "left": "neumann"},
        g_a="0", title="affine patch test with frictionless contact", times=(0.0, 0.3, 0.7, 1.0))
    # smooth manufactured plane elasticity on the unit square (left side clamped)
    u_m = [(1 + t) / 10 * sympy.sin(x) * sympy.exp(y / 2), (1 + t) / 10 * x ** 2 * sympy.cos(y)]
    scenes["mms_elastic"] = mms_scene(
        u_m, [[0, 0], [1, 0], [1, 1], [0, 1]], (4, 4),
        {"left": "dirichlet", "bottom": "neumann", "right": "neumann", "top": "neumann"},
        title="manufactured plane elasticity (no contact)", times=(0.0, 0.5, 1.0))
    return scenes


# ----------------------------------------------------------------------------------------------
# checks
# ----------------------------------------------------------------------------------------------
def check_expressions():
    e = ts.Expr("2^3*sin(PI*x) + max(x, y) - min(1, t) + ln(e) + log(E) + signum(-2) + atan2(y, x)"
                " + sqrt(abs(-4)) + floor(2.5) + tanh(0) + sinh(0) + cosh(0) + exp(0) + 1.5e-1", "k")
    x, y, t = 0.5, 1.0, 2.0
    ref = (8 * np.sin(np.pi * x) + max(x, y) - min(1, t) + 1 + 1 - 1 + np.arctan2(y, x) + 2 + 2 + 0 + 0 + 1 + 1
           + 0.15)
    check("expression: exmex functions/constants", abs(e(x, y, t) - ref) < 1e-13, f"{e(x, y, t)} vs {ref}")
    ok = True
    for bad in ["foo(x)", "z + 1", "1 +", "x^", ""]:
        try:
            ts.Expr(bad, "k")
            ok = False
        except ts.SceneError:
            pass
    check("expression: unknown names and syntax errors rejected", ok)
    c = ts.VecExpr(["0", "0*x"], "f")
    check("expression: literal zero detected", c.is_zero and not ts.VecExpr(["t", "0"], "g").is_zero)


def check_meshes():
    m = ts.structured_mesh([[0, 0], [2, 0], [2, 1], [0, 1]], 4, 3, "first")
    ok = len(m.points) == 20 and len(m.triangles) == 24 and {k: len(v) for k, v in m.boundary_segments.items()} \
        == {"bottom": 4, "right": 3, "top": 4, "left": 3}
    p = m.points
    d1, d2 = p[m.triangles[:, 1]] - p[m.triangles[:, 0]], p[m.triangles[:, 2]] - p[m.triangles[:, 0]]
    ok &= bool(np.all(d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0] > 0))
    # first diagonal of cell (0,0) joins p(0,0)=(0,0) and p(1,1)=(0.5,1/3)
    ok &= {0, 6} <= set(m.triangles[0]) and {0, 6} <= set(m.triangles[1])
    m2 = ts.structured_mesh([[0, 0], [2, 0], [2, 1], [0, 1]], 4, 3, "second")
    ok &= {1, 5} <= set(m2.triangles[0]) and {1, 5} <= set(m2.triangles[1])
    ok &= np.allclose(m.points[m.boundary_segments["right"][:, 0], 0], 2.0)
    check("mesh: structured counts, orientation, diagonals, side names", ok)
    sc = ts.load_scene(os.path.join(CASES, "trapezoid.toml"))
    sc.mesh["refine"] = 0
    g0 = ts.build_mesh(sc)
    sc.mesh["refine"] = 2
    g2 = ts.build_mesh(sc)
    d0, d2_ = ts.Discretisation(sc, g0), ts.Discretisation(sc, g2)
    ok = len(g2.triangles) == 16 * len(g0.triangles) and len(d2_.contact) == 4 * len(d0.contact)
    ok &= abs(d2_.areas.sum() - d0.areas.sum()) < 1e-12 and abs(d0.areas.sum() - 10.0) < 1e-12
    check("mesh: Gmsh reader + red refinement (area, part sizes)", ok,
          f"{len(g0.triangles)} -> {len(g2.triangles)} triangles, contact {len(d0.contact)} -> {len(d2_.contact)}")


def check_box_qp():
    rng = np.random.default_rng(1)
    worst = 0.0
    for trial in range(300):
        n = int(rng.integers(1, 30))
        A = rng.standard_normal((n, n))
        C = A @ A.T + 1e-2 * np.eye(n)
        d = rng.standard_normal(n) * rng.uniform(0.1, 10)
        w = rng.uniform(0, 2, n)
        w[rng.random(n) < 0.1] = 0.0
        mu0 = rng.uniform(-2, 2, n) if trial % 2 else None
        mu, _ = ts.box_qp(C, d, w, mu0)
        g = C @ mu - d
        feas = np.max(np.maximum(np.abs(mu) - w, 0))
        # KKT: g_i = 0 inside, g_i <= 0 at +w, g_i >= 0 at -w
        inside = np.abs(mu) < w
        kkt = max(np.max(np.abs(g[inside]), initial=0), np.max(g[(mu >= w) & (w > 0)], initial=0),
                  np.max(-g[(mu <= -w) & (w > 0)], initial=0))
        worst = max(worst, feas, kkt / (np.abs(d).max() + np.abs(C).max() * w.max()))
    check("box QP: KKT conditions on 300 random problems", worst < 1e-12, f"worst scaled violation {worst:.2e}")


def check_vi(h5path, scene_path, label):
    """Verify the discrete variational inequality at every step from the stored results."""
    import h5py
    sys.path.insert(0, HERE)
    from skfem_solve import SkfemProblem
    scene = ts.load_scene(scene_path)
    disc = ts.Discretisation(scene)
    prob = SkfemProblem(disc)
    with h5py.File(h5path, "r") as fh:
        g = fh["tresca"]
        U = g["u"][()].reshape(len(scene.times), -1)
        perm = ts.match_points(disc.midpoints, g["mesh/midpoints"][()])
        Uc = np.zeros_like(U)
        for c in range(2):
            Uc[:, 2 * perm + c] = U[:, c::2]
        sig = g["contact/sigma_t"][()]
        cperm = ts.match_points(disc.midpoints[disc.contact], g["mesh/midpoints"][()][g["contact/edges"][()]])
        mu = np.zeros_like(sig)
        mu[:, cperm] = -sig * disc.lengths[disc.contact][cperm]
    P, ic = disc.reduction()
    Kr = P.T @ prob.K @ P
    w = disc.weight
    worst_eq = worst_box = worst_dir = 0.0
    for n in range(1, len(scene.times)):
        r = P.T @ Uc[n]
        if np.max(np.abs(P @ r - Uc[n])) > 1e-13 * max(1.0, np.abs(Uc[n]).max()):
            return check(f"VI ({label}): stored u lies in the constrained space", False)
        rhs = P.T @ prob.load(scene.times[n])
        rhs[ic] -= mu[n]
        res = Kr @ r - rhs
        worst_eq = max(worst_eq, np.abs(res).max() / max(np.abs(P.T @ prob.load(scene.times[n])).max(), 1e-300))
        if len(ic):
            ds = r[ic] - (P.T @ Uc[n - 1])[ic]
            worst_box = max(worst_box, np.max(np.maximum(np.abs(mu[n]) - w, 0)) / max(w.max(), 1e-300))
            scale = max(np.abs(Uc[n]).max(), np.abs(Uc[n - 1]).max())
            moving = np.abs(ds) > 1e-10 * scale
            dev = np.abs(mu[n][moving] - w[moving] * np.sign(ds[moving]))
            worst_dir = max(worst_dir, np.max(dev, initial=0.0) / max(w.max(), 1e-300))
    return check(f"VI ({label}): equilibrium, |mu|<=w, mu=w sign(ds) on slipping edges",
                 worst_eq < 1e-9 and worst_box < 1e-12 and worst_dir < 1e-9,
                 f"eq {worst_eq:.1e}, box {worst_box:.1e}, direction {worst_dir:.1e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip the convergence study")
    ap.add_argument("--no-mpi", action="store_true", help="skip the mpirun -n 2 checks")
    ap.add_argument("--write-scenes", metavar="DIR", help="also write the generated scenes to DIR")
    ap.add_argument("--no-cases", action="store_true",
                    help="skip skfem == dolfinx on verification/cases (verification/cross_check.py covers them)")
    args = ap.parse_args()
    t_start = time.perf_counter()
    check_expressions()
    check_meshes()
    check_box_qp()

    gen = generated_scenes()
    tmp = tempfile.mkdtemp(prefix="tresca_py_")
    # the generated scenes and the solvers' results files (about 8 MB) are removed at exit (kept when a
    # check fails, see the end)
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    paths = {}
    for name, text in gen.items():
        paths[name] = os.path.join(tmp, f"{name}.toml")
        with open(paths[name], "w") as fh:
            fh.write(text)
        if args.write_scenes:
            os.makedirs(args.write_scenes, exist_ok=True)
            with open(os.path.join(args.write_scenes, f"{name}.toml"), "w") as fh:
                fh.write(text)
    for name in ("cyclic", "trapezoid"):
        paths[name] = os.path.join(CASES, f"{name}.toml")
    # Example 5.1 on the paper's n = 8 mesh (refine 2 of its 2 x 2 cells), as a scene of its own
    with open(os.path.join(CASES, "paper_example_5_1.toml")) as fh:
        ex51 = fh.read().replace("cells = [2, 2]", "cells = [8, 8]")
    assert "cells = [8, 8]" in ex51, "paper_example_5_1.toml changed: update this generator"
    paths["example51"] = os.path.join(tmp, "example51.toml")
    with open(paths["example51"], "w") as fh:
        fh.write(ex51)

    import h5py
    # patch tests and cross-checks
    for name in ("patch_elastic_first", "patch_elastic_second", "patch_contact", "mms_elastic",
                 "example51", "cyclic", "trapezoid"):
        a, b = os.path.join(tmp, f"{name}_sk.h5"), os.path.join(tmp, f"{name}_dx.h5")
        ta = solve("skfem", paths[name], a)
        tb = solve("dolfinx", paths[name], b)
        ok, line = compare(a, b)
        check(f"skfem == dolfinx on {name} (1e-8)", ok, f"{line}  [{ta:.1f} s / {tb:.1f} s]")
        if name.startswith("patch"):
            for f, lab in ((a, "skfem"), (b, "dolfinx")):
                with h5py.File(f, "r") as fh:
                    g = fh["tresca"]
                    e = max(np.max(g["errors/energy"][()]), np.max(g["errors/h1"][()]), np.max(g["errors/l2"][()]))
                    unorm = np.max(np.abs(g["u"][()]))
                check(f"patch test exact: {name} ({lab})", e < 1e-12 * max(unorm, 1e-300),
                      f"max true error {e:.2e} (max |u| {unorm:.2e})")
        if name in ("example51", "cyclic", "trapezoid", "patch_contact"):
            check_vi(a, paths[name], name)

    if not args.no_mpi:
        for name in ("cyclic", "trapezoid", "mms_elastic"):
            a, b = os.path.join(tmp, f"{name}_dx.h5"), os.path.join(tmp, f"{name}_dx2.h5")
            tb = solve("dolfinx", paths[name], b, mpi=2)
            ok, line = compare(a, b)
            check(f"dolfinx serial == mpirun -n 2 on {name} (1e-8)", ok, f"{line}  [{tb:.1f} s]")

    # the repository's verification scenes (manufactured Tresca solutions), when present
    cases = os.path.join(os.path.dirname(HERE), "verification", "cases")
    if os.path.isdir(cases) and not args.no_cases:
        for fn in sorted(os.listdir(cases)):
            if not fn.endswith(".toml"):
                continue
            name = "v_" + fn[:-5]
            paths[name] = os.path.join(cases, fn)
            a, b = os.path.join(tmp, f"{name}_sk.h5"), os.path.join(tmp, f"{name}_dx.h5")
            try:
                solve("skfem", paths[name], a)
                solve("dolfinx", paths[name], b)
            except RuntimeError as err:
                check(f"verification/cases/{fn} runs", False, str(err))
                continue
            ok, line = compare(a, b)
            check(f"skfem == dolfinx on verification/cases/{fn} (1e-8)", ok, line)

    # the Rust solver, when its binary can write results (-o)
    rust = os.path.join(os.path.dirname(HERE), "target", "release", "tresca-cr")
    if os.path.exists(rust):
        helptext = run([rust, "run", "--help"], expect_ok=False).stdout
        if "--output" in helptext or " -o" in helptext:
            for name in ("example51", "cyclic", "trapezoid", "patch_contact", "mms_elastic"):
                out = os.path.join(tmp, f"{name}_rs.h5")
                p = run([rust, "run", paths[name], "-o", out, "-q"], expect_ok=False)
                if p.returncode != 0:
                    check(f"Rust runs {name}", False, (p.stderr or p.stdout).strip()[-300:])
                    continue
                ok, line = compare(os.path.join(tmp, f"{name}_sk.h5"), out, tol=1e-8)
                check(f"skfem == Rust on {name} (1e-8)", ok, line)
        else:
            print("       (Rust binary cannot write results yet: no -o option; skipped)")

    if not args.quick:
        errs = {}
        for k in range(4):
            out = os.path.join(tmp, f"mms_r{k}.h5")
            solve("skfem", paths["mms_elastic"], out, ["--refine", str(k)])
            with h5py.File(out, "r") as fh:
                errs[k] = (fh["tresca/errors/energy"][-1], fh["tresca/errors/l2"][-1])
        rE = [np.log2(errs[k][0] / errs[k + 1][0]) for k in range(3)]
        rL = [np.log2(errs[k][1] / errs[k + 1][1]) for k in range(3)]
        check("manufactured elasticity: energy-error rate ~1, L2 rate ~2",
              0.85 < rE[-1] < 1.2 and 1.7 < rL[-1] < 2.3,
              "energy " + ", ".join(f"{r:.2f}" for r in rE) + "; L2 " + ", ".join(f"{r:.2f}" for r in rL))

    # bad input
    bad = {
        "unknown key": "[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\nfoo=1\n",
        "missing side": ("[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\n[material]\nE=1.0\nnu=0.3\n"
                         "[[boundary]]\nname='left'\nkind='dirichlet'\n[time]\nT=1.0\nsteps=2\n"),
        "bad expression": ("[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\n[material]\nE=1.0\nnu=0.3\n"
                           "[[boundary]]\nname='left'\nkind='neumann'\ntraction=['q*x','0']\n[time]\nT=1.0\nsteps=2\n"),
    }
    ok_all = True
    for label, text in bad.items():
        p = os.path.join(tmp, "bad.toml")
        with open(p, "w") as fh:
            fh.write(text)
        r = run([PY, os.path.join(HERE, "skfem_solve.py"), p, "-o", os.path.join(tmp, "bad.h5")], expect_ok=False)
        msg = r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ""
        ok_all &= r.returncode != 0 and msg.startswith("error:") and "Traceback" not in r.stderr
        print(f"       {label}: {msg}")
    check("bad scenes give a one-line error", ok_all)

    nfail = sum(not ok for _, ok in RESULTS)
    # a failed check's files are kept for its diagnosis (and with TRESCA_KEEP_TMP set, as for the Rust tests)
    keep = nfail > 0 or bool(os.environ.get("TRESCA_KEEP_TMP"))
    if keep:
        atexit.unregister(shutil.rmtree)
    print(f"\n{len(RESULTS) - nfail}/{len(RESULTS)} checks passed in {time.perf_counter() - t_start:.0f} s "
          + (f"(work files kept in {tmp})" if keep else "(work files removed)"))
    return 1 if nfail else 0


if __name__ == "__main__":
    sys.exit(main())

"""Running the three solvers of ``verification/cross_check.py`` and comparing their results files
(``tresca_py.verify.cross_check``): commands, timings, sizes, the agreement test and its one-line summary."""
import importlib.metadata
import os
import platform
import subprocess
import time

import h5py
import numpy as np

from tresca_py import compare
from tresca_py.common import BIN, MPIRUN, PY, ROOT, cmdline

TOL = 1e-8


def run_route(code, scene, out, refine, steps, mpi=0):
    """Run one solver; returns (exit status, wall seconds, command string, message)."""
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
    return p.returncode, wall, cmdline(cmd), msg


def run_code(code, scene, out, refine, steps, mpi=0):
    """Run one solver; returns (ok, wall seconds, command string, message)."""
    rc, wall, cmd, msg = run_route(code, scene, out, refine, steps, mpi)
    return rc == 0, wall, cmd, msg


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


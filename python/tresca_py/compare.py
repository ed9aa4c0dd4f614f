"""Compare two ``tresca`` results files (Rust, scikit-fem or dolfinx) of the same scene.

Usage:  python scripts/compare.py A.h5 B.h5 [--tol 1e-8] [--quiet]

Edges are matched by their midpoint coordinates (the CR nodes), contact edges likewise, so the two
files may number vertices and edges differently.  For every time node n it reports

    du     = |u_A^n - u_B^n| / |u_A^n|            (Euclidean norm of the whole DOF vector;
                                                  absolute when |u_A^n| = 0)
    dE     = |E_A^n - E_B^n| / |E_A^n|            (E = tresca/energy = a_h(u^n,u^n), when both have it)
    dsig   = |sigma_t,A - sigma_t,B|_inf / max_e gbar_e      (tangential traction on Gamma_C; with normal
             unknowns, unilateral or Coulomb, max(|d sigma_t|_inf, |p_A - p_B|_inf) / max(gbar, |sigma_t,A|, p_A))
    flags  = number of contact edges whose stick/slip state differs (with normal unknowns in both files: whose
             stick/slip/separated status differs)
    derr_* = relative difference of the true errors (energy, h1, l2), when both files have them
             (0 when both are below --err-floor, as in patch tests)

and exits with status 1 if max(du, dE, dsig, derr) > tol or is NaN; with status 2 and one ``error:`` line if
a file is not a valid results file (``tresca_py.results``: NaN/Inf in a series is refused there) or the
meshes/times do not match.  Differing
stick/slip flags are reported but only fail the comparison with --strict-flags (a flag may flip at an
edge where |mu_e| = w_e and the slip increment vanishes up to rounding).
"""
import argparse
import math
import sys

import numpy as np
from scipy.spatial import cKDTree

from . import results


class CompareError(ValueError):
    """The two files cannot be compared (unreadable, invalid, different meshes or time nodes)."""


def load(path):
    """The arrays compared, from a validated results file (``tresca_py.results``: NaN/Inf are refused)."""
    try:
        r = results.read(path)
    except results.ResultsError as err:
        raise CompareError(str(err)) from None
    out = {"times": r.times, "u": r.u, "mid": r.mesh.midpoints, "energy": r.energy, "solver": str(r.attrs["solver"])}
    if r.contact is not None:
        c = r.contact
        out.update(cmid=r.mesh.midpoints[c.edges], sigma_t=c.sigma_t, state=c.state, slip=c.slip, g=c.g,
                   pressure=c.pressure, status=c.status)
    if r.errors is not None:
        out["errors"] = dict(r.errors)
    return out


def match(ref, other, what):
    if len(ref) != len(other):
        raise CompareError(f"different number of {what}: {len(ref)} vs {len(other)}")
    if len(ref) == 0:
        return np.zeros(0, dtype=int)
    scale = max(1.0, float(np.max(np.abs(ref))))
    dist, idx = cKDTree(ref).query(other)
    if np.max(dist) > 1e-9 * scale or len(np.unique(idx)) != len(idx):
        raise CompareError(f"{what} do not match (max midpoint distance {np.max(dist):.3e})")
    return idx


def rel_l2(a, b):
    """‖a − b‖₂ / ‖a‖₂ (‖a − b‖₂ when a vanishes)."""
    na = np.linalg.norm(a)
    return np.linalg.norm(a - b) / na if na > 0 else np.linalg.norm(a - b)


# True errors below this fraction of the discrete solution's energy norm |||u_h||| = (2 E)^(1/2) are rounding: the
# exact solution lies in the discrete space (a linear field, which CR reproduces), and what is left is the solve's
# rounding, about κ(a_h)·eps·|||u|||, which differs between codes as du does. Their relative difference carries no
# information (|e_A − e_B| ≤ |||u_A − u_B||| already bounds it through du); the manufactured cases with a
# discretisation error have errors of 1e-4 … 1e-1 of |||u_h||| at the levels compared, far above it.
ROUNDING_LEVEL = 1e-10


def rounding_level(A, B, n):
    """The error below which the true errors of time node n are rounding (0 without energies)."""
    if "energy" not in A or "energy" not in B:
        return 0.0
    return ROUNDING_LEVEL * math.sqrt(2.0 * max(abs(A["energy"][n]), abs(B["energy"][n])))


def compare_files(path_a, path_b, err_floor=1e-12):
    """Compare two results files; returns a dict with the worst values ``du, dE, dsig, derr``, the number
    of differing stick/slip ``flags`` (summed over time nodes), the per-node ``rows`` (n, t, du, dE, dsig,
    flags, [derr_k...]), the compared error names ``errors`` and the solver names.  Raises CompareError
    when the files cannot be compared."""
    A, B = load(path_a), load(path_b)
    if A["times"].shape != B["times"].shape or np.max(np.abs(A["times"] - B["times"])) > 1e-12:
        raise CompareError(f"time nodes differ ({len(A['times'])} vs {len(B['times'])})")
    # B edge k corresponds to A edge perm[k]
    perm = match(A["mid"], B["mid"], "edges")
    uB = np.empty_like(A["u"])
    uB[:, perm] = B["u"]
    N1 = len(A["times"])
    has_c = "cmid" in A and "cmid" in B and len(A["cmid"]) > 0
    if ("cmid" in A and len(A["cmid"])) != ("cmid" in B and len(B["cmid"])):
        raise CompareError("one file has contact edges, the other has none")
    if has_c:
        cperm = match(A["cmid"], B["cmid"], "contact edges")
        sB = np.empty_like(A["sigma_t"])
        sB[:, cperm] = B["sigma_t"]
        flag = "status" if A["status"] is not None and B["status"] is not None else "state"   # status: + separated
        stB = np.empty_like(A[flag])
        stB[:, cperm] = B[flag]
        gscale = max(float(np.max(A["g"])), 1e-300)
        if (A["pressure"] is None) != (B["pressure"] is None):
            raise CompareError("one file has contact pressures (normal unknowns), the other has none")
        if A["pressure"] is not None:
            pB = np.empty_like(A["pressure"])
            pB[:, cperm] = B["pressure"]
            gscale = max(gscale, float(np.max(np.abs(A["sigma_t"]))), float(np.max(np.abs(A["pressure"]))))
    errs = sorted(set(A.get("errors", {})) & set(B.get("errors", {})))
    worst = dict(du=0.0, dE=0.0, dsig=0.0, derr=0.0)
    nflags = 0
    rows = []
    for n in range(N1):
        du = rel_l2(A["u"][n].ravel(), uB[n].ravel())
        dE = (abs(A["energy"][n] - B["energy"][n]) / abs(A["energy"][n]) if abs(A["energy"][n]) > 0
              else abs(B["energy"][n])) if "energy" in A and "energy" in B else 0.0
        dsig = float(np.max(np.abs(A["sigma_t"][n] - sB[n]))) / gscale if has_c else 0.0
        if has_c and A["pressure"] is not None:
            dsig = max(dsig, float(np.max(np.abs(A["pressure"][n] - pB[n]))) / gscale)
        fl = int(np.sum(A[flag][n] != stB[n])) if has_c else 0
        floor = max(err_floor, rounding_level(A, B, n))
        de = [abs(A["errors"][k][n] - B["errors"][k][n]) / max(abs(A["errors"][k][n]), abs(B["errors"][k][n]))
              if max(abs(A["errors"][k][n]), abs(B["errors"][k][n])) > floor else 0.0 for k in errs]
        # np.maximum propagates NaN (Python's max(0.0, nan) is 0.0, which would pass a NaN difference)
        worst["du"] = float(np.maximum(worst["du"], du))
        worst["dE"] = float(np.maximum(worst["dE"], dE))
        worst["dsig"] = float(np.maximum(worst["dsig"], dsig))
        worst["derr"] = float(np.max(np.array([worst["derr"]] + de)))
        nflags += fl
        rows.append((n, float(A["times"][n]), du, dE, dsig, fl, de))
    return dict(worst, flags=nflags, rows=rows, errors=errs, solver_a=A["solver"], solver_b=B["solver"],
                n_times=N1, has_errors=bool(errs), has_energy="energy" in A and "energy" in B)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--quiet", action="store_true", help="print only the summary")
    ap.add_argument("--err-floor", type=float, default=1e-12,
                    help="true errors below this (absolute) count as equal, e.g. in patch tests (1e-12)")
    ap.add_argument("--strict-flags", action="store_true", help="fail on any differing stick/slip flag")
    args = ap.parse_args(argv)
    if not (math.isfinite(args.tol) and args.tol >= 0) or not (math.isfinite(args.err_floor) and args.err_floor >= 0):
        print("error: --tol and --err-floor must be finite numbers >= 0", file=sys.stderr)
        return 2
    try:
        r = compare_files(args.a, args.b, args.err_floor)
    except CompareError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    if not args.quiet:
        head = f"{'n':>5} {'t':>10} {'du':>10} {'dE':>10} {'dsig':>10} {'flags':>5}"
        head += "".join(f" {'derr_' + k:>11}" for k in r["errors"])
        print(f"A = {args.a} ({r['solver_a']}), B = {args.b} ({r['solver_b']})")
        print(head)
        for n, t, du, dE, dsig, fl, de in r["rows"]:
            print(f"{n:5d} {t:10.6g} {du:10.3e} {dE:10.3e} {dsig:10.3e} {fl:5d}" + "".join(f" {x:11.3e}" for x in de))
    m = np.max([r[k] for k in ("du", "dE", "dsig", "derr")])
    ok = bool(np.isfinite(m) and m <= args.tol) and (r["flags"] == 0 or not args.strict_flags)
    print(f"max du = {r['du']:.3e}, max dE = {r['dE']:.3e}, max dsig = {r['dsig']:.3e}, "
          f"max derr = {r['derr']:.3e}, differing stick/slip flags = {r['flags']} "
          f"-> {'PASS' if ok else 'FAIL'} (tol {args.tol:g})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())

"""Bit-identity check for refactors: a refactor changes no number.

Usage:
    python verification/bit_identity.py run DIR [--bin PATH] [--threads N]   # every case's results into DIR
    python verification/bit_identity.py compare DIR_A DIR_B     # compare them dataset by dataset
    python verification/bit_identity.py compare DIR_A DIR_B --rel 1e-10   # floats within a relative tolerance

`run` solves every scene of ``verification/cases/`` (at its own refine and steps, and at one finer level) and
the paper's Example 5.1 levels of Tables 5.1/5.2 (refine k, N = 40·2^k, k = 0..4), with the SSN, Uzawa and PDAS
solvers where the scene has contact. `compare` reads every dataset and attribute under ``/tresca`` and
``/VTKHDF`` with h5py and requires the bytes to be equal, except what is not a number of the method: wall times
(``steps/wall_time``, ``setup_times``, the Python solvers' ``*_time`` and ``*peak_rss_mb`` attributes, and
``steps/checksum``, which hashes the wall time with the rest of a step), the build (``version``,
``git_commit``). It prints one line per file and exits non-zero
if any value differs. With ``--rel TOL`` floating-point values may differ by TOL relative to the largest
magnitude of their dataset (max |a - b| <= TOL max |a|, for changes that move results by rounding only;
float32 visualisation copies within max(TOL, 1e-6), the solvers' residuals within 1e-12 absolute);
everything else (integers, flags, strings, shapes) must still be equal; the largest relative differences
of every file are printed. Like is compared with like: files written with different thread counts
(``/tresca@threads``; 1 in files of versions before it) differ unless ``--rel`` is given, which notes the
counts (``run --threads N`` passes ``--threads N`` to the binary). ``scene_path`` (where the scene file
was) is not compared; a dataset added by a later version (``tresca/steps/checksum``) is compared only
when both files hold it.
"""
import argparse
import glob
import os
import subprocess
import sys

import h5py
import numpy as np

from tresca_py.common import ROOT, rel_to
# not numbers of the method: they change from run to run or build to build
# steps/checksum hashes each step's rows including steps/wall_time, so it changes from run to run too (its
# agreement with the rows is what --resume and scripts/check_results.py verify)
VOLATILE = {"steps/wall_time", "steps/checksum", "setup_times", "version", "git_commit", "scene_path",
            # the Python solvers' timings and peak memory (attributes of /tresca)
            "assembly_time", "factor_time", "total_time", "setup_time", "step_time_median", "peak_rss_mb",
            "setup_peak_rss_mb"}
# added by a later version (issue 18: per-step checksums): compared when both files have it, else skipped
ADDED = {"tresca/steps/checksum"} | {
    # issue 30: the per-step energy audit (src/stepping/audit.rs)
    f"tresca/steps/{k}" for k in ("external_work", "boundary_work", "stored_energy", "friction_dissipation",
                                  "euler_dissipation", "balance_residual")
}


# the thread count of the run that wrote a file (files of versions before it: 1, every kernel that could
# change a bit with the count was sequential then)
THREADS = "tresca@threads"


def runs():
    """(name, scene, extra CLI arguments) of every run compared."""
    out = []
    for scene in sorted(glob.glob(os.path.join(ROOT, "verification", "cases", "*.toml"))):
        name = os.path.splitext(os.path.basename(scene))[0]
        out.append((name, scene, []))
        out.append((name + "_r1", scene, ["--refine", "1"]))
    paper = os.path.join(ROOT, "verification", "cases", "paper_example_5_1.toml")
    for k in range(5):
        out.append((f"paper_{k}", paper, ["--refine", str(k), "--steps", str(40 * 2**k)]))
    for solver in ("uzawa", "pdas"):
        out.append((f"paper_2_{solver}", paper, ["--refine", "2", "--steps", "160", "--solver", solver]))
        front = os.path.join(ROOT, "verification", "cases", "mms_front.toml")
        out.append((f"mms_front_{solver}", front, ["--solver", solver]))
    return out


def cmd_run(args):
    os.makedirs(args.dir, exist_ok=True)
    failed = 0
    for name, scene, extra in runs():
        path = os.path.join(args.dir, name + ".h5")
        threads = [] if args.threads is None else ["--threads", str(args.threads)]
        p = subprocess.run([args.bin, "run", scene, "-o", path, "--force", "-q", *threads, *extra],
                           capture_output=True, text=True, cwd=ROOT)
        status = "ok" if p.returncode == 0 else f"exit {p.returncode}: {p.stderr.strip()[-200:]}"
        failed += p.returncode != 0
        print(f"{name:28s} {status}")
    return 0 if failed == 0 else 1


def items(f):
    """{path: bytes-comparable value} of every dataset and attribute under /tresca and /VTKHDF (a Python
    solver's file has no /VTKHDF; a group in one file only differs by its keys)."""
    out = {}
    for group in (g for g in ("tresca", "VTKHDF") if g in f):
        def visit(name, obj, group=group):
            if isinstance(obj, h5py.Dataset):
                out[f"{group}/{name}"] = obj[()]
            for k, v in obj.attrs.items():
                out[f"{group}/{name}@{k}"] = v

        g = f[group]
        for k, v in g.attrs.items():
            out[f"{group}@{k}"] = v
        g.visititems(visit)
    return out


def dataset_diff(a, b):
    """max |a - b| / max |a| (tresca_py.common.rel_to) over the finite entries of two floating-point datasets
    of equal shape and dtype; inf when their non-finite entries differ or a vanishes and b does not; None
    when they cannot be compared so."""
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape or a.dtype != b.dtype or a.dtype.kind != "f" or a.size == 0:
        return None
    if not (np.array_equal(np.isfinite(a), np.isfinite(b))):
        return np.inf
    fa, fb = a[np.isfinite(a)], b[np.isfinite(b)]
    if fa.size == 0 or np.array_equal(fa, fb):
        return 0.0
    return rel_to(fb, fa) if np.max(np.abs(fa)) > 0 else np.inf


# --rel: the solvers' natural residuals are round-off quantities (~1e-15 of the force scale, far below any
# tolerance), compared by absolute difference; float32 visualisation copies (VTKHDF) by a few float32 ulps
RESIDUAL_ABS = 1e-12
FLOAT32_REL = 1e-6


def same(a, b, rel=None, key=""):
    if rel is not None:
        if key.endswith("residual"):
            a, b = np.asarray(a), np.asarray(b)
            return a.shape == b.shape and bool(np.all(np.abs(a - b) <= RESIDUAL_ABS))
        r = dataset_diff(a, b)
        if r is not None:
            return r <= (max(rel, FLOAT32_REL) if np.asarray(a).dtype == np.float32 else rel)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()
    return a == b


def cmd_compare(args):
    bad = 0
    files = sorted(os.path.basename(p) for p in glob.glob(os.path.join(args.a, "*.h5")))
    missing = sorted(set(os.path.basename(p) for p in glob.glob(os.path.join(args.b, "*.h5"))) ^ set(files))
    for name in missing:
        print(f"{name:28s} MISSING in one directory")
        bad += 1
    for name in files:
        pb = os.path.join(args.b, name)
        if not os.path.exists(pb):
            continue
        with h5py.File(os.path.join(args.a, name), "r") as fa, h5py.File(pb, "r") as fb:
            ia, ib = items(fa), items(fb)
        keys = sorted(k for k in set(ia) | set(ib)
                      if k.split("@")[-1] not in VOLATILE and k.split("@")[0].removeprefix("tresca/") not in VOLATILE)
        keys = [k for k in keys if not (k in ADDED and (k in ia) != (k in ib)) and k != THREADS]
        diff = [k for k in keys if k not in ia or k not in ib or not same(ia[k], ib[k], args.rel, k)]
        counts = (int(ia.get(THREADS, 1)), int(ib.get(THREADS, 1)))
        worst = "" if counts[0] == counts[1] else f"  threads {counts[0]} vs {counts[1]}"
        if counts[0] != counts[1] and args.rel is None:
            diff.insert(0, f"{THREADS} (compare like with like, or give --rel)")
        if args.rel is not None:
            for kind, sel in (("float64", np.float64), ("float32", np.float32)):
                r = [dataset_diff(ia[k], ib[k]) for k in keys if k in ia and k in ib and not k.endswith("residual")
                     and np.asarray(ia[k]).dtype == sel]
                worst += f"  max rel {kind} {max([x for x in r if x is not None] + [0.0]):.1e}"
        ok = "identical" if args.rel is None else f"within {args.rel:g}"
        print(f"{name:28s} {len(keys):3d} items  {ok if not diff else 'DIFFER: ' + ', '.join(diff[:6])}{worst}")
        bad += bool(diff)
    print(f"{len(files)} files, {bad} differ")
    return 0 if bad == 0 else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("dir")
    r.add_argument("--bin", default=os.path.join(ROOT, "target", "release", "tresca-cr"))
    r.add_argument("--threads", type=int, default=None, help="the binary's --threads (default: its own)")
    c = sub.add_parser("compare")
    c.add_argument("a")
    c.add_argument("b")
    c.add_argument("--rel", type=float, default=None, help="relative tolerance for floating-point values")
    args = ap.parse_args()
    sys.exit(cmd_run(args) if args.cmd == "run" else cmd_compare(args))

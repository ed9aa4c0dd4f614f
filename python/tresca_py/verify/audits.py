"""EB1: the energy audit (:mod:`tresca_py.audit`, as ``scripts/check_results.py`` runs it) on every results file
that tresca-cr writes during ``make verify`` (issue 30 §4: "check the residual against the solver tolerance
on every case").

After each study of :mod:`tresca_py.verify.run_all` the harness looks for the HDF5 files that study wrote
under the output directory (new or modified against a :func:`snapshot` taken before it) and checks each one
that carries the audit series (tresca-cr's files; the Python re-implementations and older versions write none,
they are listed as skipped): the stored residual is the residual of the stored terms, |ΔE + D + j − W − W_Γ| ≤
(``audit.BALANCE_REL`` + ``audit.rounding``) × the largest work of a step (the bound and its reason:
:mod:`tresca_py.audit`), the dissipations are non-negative. One result per study, ``EB1-<study>``, lists every
file checked with its largest relative residual and the solver tolerance it ran with; a study that wrote no
tresca-cr file records nothing (its cases are ``tresca-cr study`` runs, which keep no results file). So that
those cases are audited too, the study ``audit`` (:func:`run_cases`) runs every scene of
``verification/cases/`` and ``verification/external/scenes/`` once with a results file (refine 1, the scene's
own steps; refine 0 for the Gmsh scenes, whose files are already fine) and is audited like the others
(``EB1-audit``: 19 files in 11 s). ``verification/stability.py`` audits the files of its cases, which live in
a temporary directory, itself (``EB1-stability``, :func:`record`).
"""
import glob
import os
import subprocess

import h5py

from tresca_py import audit, results
from tresca_py.common import BIN, ROOT

#: the scene directories whose every scene ``run_cases`` runs once
CASE_DIRS = ("verification/cases", "verification/external/scenes")


def snapshot(root):
    """{path: modification time (ns)} of the ``.h5`` files under ``root``."""
    found = {}
    for d, _, names in os.walk(root):
        for n in names:
            if n.endswith(".h5"):
                p = os.path.join(d, n)
                found[p] = os.stat(p).st_mtime_ns
    return found


def written_after(root, before):
    """The ``.h5`` files under ``root`` that are new or modified against the :func:`snapshot` ``before``."""
    return sorted(p for p, t in snapshot(root).items() if before.get(p) != t)


def check_file(path):
    """(audited, problems, rel, detail) of one file: ``audited`` False for a file without the audit series
    (a file with them that does not read as a results file is a problem); ``rel`` the largest |residual|
    relative to the largest work of a step."""
    try:
        with h5py.File(path, "r") as f:
            steps = f.get("tresca/steps")
            if steps is None or not all(k in steps for k in audit.SERIES):
                return False, [], 0.0, "no audit series"
            tol = f["tresca"].attrs.get("tol")
        r = results.read(path, verify=False)
    except (OSError, results.ResultsError) as err:
        return True, [f"unreadable: {str(err)[:200]}"], float("nan"), "unreadable"
    a = audit.read(r.path, r.completed)
    scale = audit.largest_work(a)
    res = float(abs(a["balance_residual"]).max()) if len(a["balance_residual"]) else 0.0
    rel = res / scale if scale > 0 else 0.0
    tol_txt = f", solver tol {float(tol):.0e}" if tol is not None else ""
    allowance = audit.rounding(r.path, audit.largest_work(a))
    return True, audit.problems(a, allowance), rel, (f"{rel:.1e} ({r.completed} steps{tol_txt}, bound "
                                                     f"{audit.BALANCE_REL + allowance:.1e})")


def audit_study(hs, name, before, root=None):
    """Record ``EB1-<name>`` for the tresca-cr results files the study wrote under ``root`` (default: the
    harness's output directory): those new or modified against the :func:`snapshot` ``before``; returns the
    per-file lines (empty: nothing recorded)."""
    return record(hs, name, written_after(root or hs.out, before))


def record(hs, name, paths):
    """Record ``EB1-<name>`` for the tresca-cr results files among ``paths`` (nothing when there is none);
    returns the per-file lines."""
    checked, skipped, failed, worst = [], [], [], 0.0
    for path in paths:
        name_rel = os.path.relpath(path, ROOT)
        audited, problems, rel, detail = check_file(path)
        if not audited:
            skipped.append(f"{name_rel}: {detail}")
            continue
        worst = max(worst, rel)
        checked.append(f"{name_rel}: {detail}")
        failed += [f"{name_rel}: {m}" for m in problems]
    if not checked:
        return []
    measured = (f"{len(checked)} files, {len(failed)} problems" + (f" ({'; '.join(failed)[:600]})" if failed else "")
                + f"; largest |residual| / largest work of a step {worst:.1e}; per file: " + "; ".join(checked)
                + (f"; skipped {len(skipped)} without the audit" if skipped else ""))
    hs.require(f"EB1-{name}", not failed, measured,
               statement=f"The solver shall balance the energy of every step, a_h(uⁿ,δuⁿ) + j_h(δuⁿ) = "
                         f"(lⁿ,δuⁿ) + W_Γⁿ, to {audit.BALANCE_REL:g} of the largest work of a step plus the "
                         f"rounding allowance in every results file that the study `{name}` writes with tresca-cr")
    return checked


def run_cases(hs, quick=False):
    """Run every scene of :data:`CASE_DIRS` once with a results file under ``<out>/audit/`` (what the studies'
    ``tresca-cr study`` runs keep none of); a scene that does not run is a failed ``EB1-audit-run-<name>``.
    ``quick``: refine 0 throughout."""
    work = os.path.join(hs.out, "audit")
    os.makedirs(work, exist_ok=True)
    for scene in sorted(p for d in CASE_DIRS for p in glob.glob(os.path.join(ROOT, d, "*.toml"))):
        name = os.path.splitext(os.path.basename(scene))[0]
        with open(scene, encoding="utf-8") as f:
            gmsh = any(line.strip().startswith("file") for line in f)
        refine = "0" if quick or gmsh else "1"
        cmd = [BIN, "run", scene, "--refine", refine, "-o", os.path.join(work, f"{name}.h5"), "--force", "-q"]
        p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
        if p.returncode != 0:
            hs.require(f"EB1-audit-run-{name}", False, f"exit {p.returncode}: {p.stderr.strip()[-300:]}",
                       statement=f"The solver shall run {os.path.relpath(scene, ROOT)} for its energy audit",
                       command=" ".join(os.path.relpath(c, ROOT) if c.startswith(ROOT) else c for c in cmd))

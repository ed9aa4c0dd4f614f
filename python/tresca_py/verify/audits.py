"""A1: the energy audit (:mod:`tresca_py.audit`, as ``scripts/check_results.py`` runs it) on every results file
that tresca-cr writes during ``make verify`` (issue 30 §4: "check the residual against the solver tolerance
on every case").

After each study of :mod:`tresca_py.verify.run_all` the harness looks for the HDF5 files that study wrote
under the output directory (modified since the study started) and checks each one that carries the audit
series (tresca-cr's files; the Python re-implementations and older versions write none, they are listed as
skipped): the stored residual is the residual of the stored terms, |ΔE + D + j − W − W_Γ| ≤
``audit.BALANCE_REL`` × the largest work of a step (the bound and its reason: :mod:`tresca_py.audit`), the
dissipations are non-negative. One result per study, ``A1-<study>``, lists every file checked with its
largest relative residual and the solver tolerance it ran with; a study that wrote no tresca-cr file
records nothing (its cases are ``tresca-cr study`` runs, which keep no results file).
"""
import os

import h5py

from tresca_py import audit, results
from tresca_py.common import ROOT


def written_since(root, since):
    """The ``.h5`` files under ``root`` modified at or after ``since`` (a time.time() value), sorted."""
    found = []
    for d, _, names in os.walk(root):
        for n in names:
            p = os.path.join(d, n)
            if n.endswith(".h5") and os.path.getmtime(p) >= since:
                found.append(p)
    return sorted(found)


def check_file(path):
    """(audited, problems, detail) of one file: ``audited`` False for a file without the audit series; a file
    with them that does not read as a results file is a problem."""
    try:
        with h5py.File(path, "r") as f:
            steps = f.get("tresca/steps")
            if steps is None or not all(k in steps for k in audit.SERIES):
                return False, [], "no audit series"
            tol = f["tresca"].attrs.get("tol")
        r = results.read(path, verify=False)
    except (OSError, results.ResultsError) as err:
        return True, [f"unreadable: {str(err)[:200]}"], "unreadable"
    a = audit.read(r.path, r.completed)
    scale = audit.largest_work(a)
    res = float(abs(a["balance_residual"]).max()) if len(a["balance_residual"]) else 0.0
    rel = res / scale if scale > 0 else 0.0
    tol_txt = f", solver tol {float(tol):.0e}" if tol is not None else ""
    return True, audit.problems(a), f"{rel:.1e} of the largest work ({r.completed} steps{tol_txt})"


def audit_study(hs, name, since, root=None):
    """Record ``A1-<name>`` for the tresca-cr results files the study wrote under ``root`` (default: the
    harness's output directory) since ``since``; returns the per-file lines (empty: nothing recorded)."""
    root = root or hs.out
    checked, skipped, failed = [], [], []
    for path in written_since(root, since):
        rel = os.path.relpath(path, ROOT)
        audited, problems, detail = check_file(path)
        if not audited:
            skipped.append(f"{rel}: {detail}")
            continue
        checked.append(f"{rel}: {detail}")
        failed += [f"{rel}: {m}" for m in problems]
    if not checked:
        return []
    measured = (f"{len(checked)} files, {len(failed)} problems" + (f" ({'; '.join(failed)[:600]})" if failed else "")
                + "; " + "; ".join(checked) + (f"; skipped {len(skipped)} without the audit" if skipped else ""))
    hs.require(f"A1-{name}", not failed, measured,
               statement=f"The solver shall balance the energy of every step, a_h(uⁿ,δuⁿ) + j_h(δuⁿ) = (lⁿ,δuⁿ) "
                         f"+ W_Γⁿ, to {audit.BALANCE_REL:g} of the largest work of a step in every results file "
                         f"that the study `{name}` writes with tresca-cr")
    return checked

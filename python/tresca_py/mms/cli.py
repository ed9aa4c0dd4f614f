"""The derivation's command line (verification/mms/derive.py): derive and check every case of
tresca_py.mms.cases and the L-shape, run the self-test, write the scenes. derive_check_write is the flow it
shares with the boundary-data cases' command line (tresca_py.mms.boundary_checks)."""
import argparse
import pathlib
import sys

from tresca_py.common import CASES as CASES_DIR
from tresca_py.mms.cases import CASES
from tresca_py.mms.cases import selftest as tresca_selftest
from tresca_py.mms.checks import run_checks
from tresca_py.mms.derive import CheckFailed
from tresca_py.mms.exmex import NotPrintable
from tresca_py.mms.lshape import case_lshape
from tresca_py.mms.lshape import check_toml as check_lshape_toml
from tresca_py.mms.lshape import run_checks as run_lshape_checks
from tresca_py.mms.lshape import scene_text as lshape_text
from tresca_py.mms.scene_toml import check_toml, scene_text
from tresca_py.mms.signorini_checks import UNILATERAL_CASES
from tresca_py.mms.signorini_checks import run_checks as run_signorini_checks
from tresca_py.mms.signorini_checks import selftest as signorini_selftest


def derive_each(makers, run):
    """Derive and check every case ``make()`` of ``makers`` with ``run(case, log)``, printing as it goes;
    returns the derived cases."""
    derived = []
    for make in makers:
        case = make()
        print("== %s: %s" % (case["name"], case["title"]))
        derived.append(run(case, lambda msg: print("   " + msg)))
    return derived


def derive_check_write(args, derive_all, selftest=None):
    """The flow of the derivation command lines: ``derive_all()`` derives and checks, returning the scenes
    to write as (file name, text, check) triples; then ``selftest()`` (when given) shows that wrong data are
    rejected. A CheckFailed or NotPrintable ends the program with status 1. Unless ``args.check``, each
    scene is written into ``args.out`` and ``check(path)`` re-reads it."""
    try:
        scenes = derive_all()
        if selftest is not None:
            print("== selftest: deliberately wrong data must be rejected")
            selftest()
    except (CheckFailed, NotPrintable) as err:
        print("\nCHECK FAILED: %s" % err, file=sys.stderr)
        sys.exit(1)
    if args.check:
        print("all checks passed (nothing written)")
        return
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, text, check in scenes:
        path = out / name
        path.write_text(text)
        check(path)
        print("wrote %s" % path)
    print("all checks passed")


def scene_of(d, text):
    """The (file name, text, check) triple of a derived case ``d`` whose scene text is ``text``."""
    return d["name"] + ".toml", text, lambda path: check_toml(path, d)


def derive_all(exmex):
    """Every case of tresca_py.mms.cases, the L-shape and the unilateral cases of tresca_py.mms.signorini, derived
    and checked: their scenes."""
    def run(case, log):
        d = run_checks(case, exmex, log)
        log("longest printed expression: %d characters" % max(len(v) for v in d["str"].values()))
        return d
    derived = derive_each(CASES, run)
    print("== mms_lshape: the L-shape with the re-entrant corner's singularity (tresca_py/mms/lshape.py)")
    lshape = run_lshape_checks(case_lshape(), lambda msg: print("   " + msg))
    text = lshape_text(lshape)
    unilateral = derive_each(UNILATERAL_CASES, run_signorini_checks)
    return [scene_of(d, scene_text(d)) for d in derived] + [
        ("mms_lshape.toml", text, lambda path: check_lshape_toml(path.read_text(), lshape))] + [
        scene_of(d, scene_text(d)) for d in unilateral]


def selftest():
    """The self-tests of the Tresca cases and of the unilateral ones."""
    tresca_selftest()
    signorini_selftest()


def main():
    ap = argparse.ArgumentParser(description="Manufactured Tresca problems with exact solutions for tresca-cr.")
    ap.add_argument("--check", action="store_true", help="derive and check only, write nothing")
    ap.add_argument("--exmex", metavar="BIN", help="binary evaluating 'expr\\tt\\tx\\ty' lines with exmex")
    ap.add_argument("--no-selftest", action="store_true", help="skip the check that wrong data are rejected")
    ap.add_argument("--out", default=CASES_DIR, help="output directory (default verification/cases)")
    args = ap.parse_args()
    derive_check_write(args, lambda: derive_all(args.exmex), None if args.no_selftest else selftest)

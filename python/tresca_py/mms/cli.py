"""The derivation's command line (verification/mms/derive.py): derive and check every case of
tresca_py.mms.cases and the L-shape, run the self-test, write the scenes."""
import argparse
import pathlib
import sys

from tresca_py.common import CASES as CASES_DIR
from tresca_py.mms.cases import CASES, selftest
from tresca_py.mms.checks import run_checks
from tresca_py.mms.derive import CheckFailed
from tresca_py.mms.exmex import NotPrintable
from tresca_py.mms.lshape import case_lshape
from tresca_py.mms.lshape import check_toml as check_lshape_toml
from tresca_py.mms.lshape import run_checks as run_lshape_checks
from tresca_py.mms.lshape import scene_text as lshape_text
from tresca_py.mms.scene_toml import check_toml, write_toml


def main():
    ap = argparse.ArgumentParser(description="Manufactured Tresca problems with exact solutions for tresca-cr.")
    ap.add_argument("--check", action="store_true", help="derive and check only, write nothing")
    ap.add_argument("--exmex", metavar="BIN", help="binary evaluating 'expr\\tt\\tx\\ty' lines with exmex")
    ap.add_argument("--no-selftest", action="store_true", help="skip the check that wrong data are rejected")
    ap.add_argument("--out", default=CASES_DIR, help="output directory (default verification/cases)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    derived = []
    try:
        for make in CASES:
            case = make()
            print("== %s: %s" % (case["name"], case["title"]))
            def log(msg):
                print("   " + msg)
            d = run_checks(case, args.exmex, log)
            log("longest printed expression: %d characters" % max(len(v) for v in d["str"].values()))
            derived.append(d)
        print("== mms_lshape: the L-shape with the re-entrant corner's singularity (tresca_py/mms/lshape.py)")
        lshape = run_lshape_checks(case_lshape(), lambda msg: print("   " + msg))
        if not args.no_selftest:
            print("== selftest: deliberately wrong data must be rejected")
            selftest()
    except (CheckFailed, NotPrintable) as err:
        print("\nCHECK FAILED: %s" % err, file=sys.stderr)
        sys.exit(1)
    if args.check:
        print("all checks passed (nothing written)")
        return
    out.mkdir(parents=True, exist_ok=True)
    for d in derived:
        path = out / (d["name"] + ".toml")
        write_toml(d, path)
        check_toml(path, d)
        print("wrote %s" % path)
    text = lshape_text(lshape)
    check_lshape_toml(text, lshape)
    (out / "mms_lshape.toml").write_text(text)
    print("wrote %s" % (out / "mms_lshape.toml"))
    print("all checks passed")

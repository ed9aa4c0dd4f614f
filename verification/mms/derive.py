#!/usr/bin/env python3
"""Manufactured Tresca problems with exact solutions for tresca-cr.

Run from the repository root:

    .venv/bin/python verification/mms/derive.py            # derive, check, write verification/cases/*.toml
    .venv/bin/python verification/mms/derive.py --check    # derive and check only, write nothing
    .venv/bin/python verification/mms/derive.py --no-selftest   # skip the mutant self-test (halves the time)
    .venv/bin/python verification/mms/derive.py --exmex BIN   # also evaluate every emitted string with a
                                                              # real exmex binary (see README.md)

For every case an exact displacement u(x, y, t) is chosen; sympy then derives

    f   = -div sigma(u)                  body force,
    g   = sigma(u) n                     traction on every Neumann side,
    g_a (time independent)               friction bound on Gamma_C,
    u0  = u(., 0)                        initial value,
    grad u                               for the solver's true-error computation,

prints all of them in the syntax of the Rust `exmex` crate, parses the printed strings back
into sympy and compares them numerically with the originals, and then CHECKS the strong form of
the problem pointwise on fine grids in space and time (equilibrium, u = 0 on Gamma_D, u.n = 0 on
Gamma_C, |sigma_t| <= g_a, stick where |sigma_t| < g_a, u_t' = -theta sigma_t with theta >= 0
where slipping, compatibility of u0). Any failed check aborts with a non-zero exit status and no
file is written.

Conventions (those of README.md of the repository): n outward unit normal, tau = (-n_y, n_x),
sigma_t = sigma(u) n - (sigma(u) n . n) n; the solver reports sigma_t . tau and the slip u . tau.

Piecewise building blocks (all C^2 in their argument, so u(., t) is in H^2 and even W^{3,inf}):
  PosPow(z, n) = max(0, z)^n                 (n = 3 in the solutions; derivatives n PosPow(z, n-1))
  SStep(z, d)  = d-th derivative of S(min(max(z, 0), 1)),  S(c) = 10c^3 - 15c^4 + 6c^5
They are sympy Functions with explicit derivative rules, so sympy differentiates them exactly, and
the printer writes them with max/min. Derivatives that are discontinuous (Heaviside-like) are never
printed; they only occur in the time derivatives used by the checks.

Everything is exact rational arithmetic until the numerical checks, so the output is deterministic.
"""
import argparse
import pathlib
import sys

import sympy as sp

# the names below are the derivation's vocabulary, re-exported for the case scripts that build on it
# (verification/bench/make_mms_poly.py, verification/mms/cases_boundary.py)
from tresca_py.expr import symbols
from tresca_py.mms.blocks import PosPow, SStep, Step, lam  # noqa: F401
from tresca_py.mms.cases import CASES, selftest
from tresca_py.mms.checks import run_checks
from tresca_py.mms.derive import CheckFailed, derive, require  # noqa: F401
from tresca_py.mms.elasticity import (PHI0, PHI1, SIDES, Xs, Ys, body_force, grad_of, lame,  # noqa: F401
                                      local_field, side_geometry, side_normal_exact, stress, to_global)
from tresca_py.mms.exmex import NotPrintable, ex  # noqa: F401
from tresca_py.mms.lshape import case_lshape
from tresca_py.mms.lshape import check_toml as check_lshape_toml
from tresca_py.mms.lshape import run_checks as run_lshape_checks
from tresca_py.mms.lshape import scene_text as lshape_text
from tresca_py.mms.scene_toml import SOLVER, check_toml, write_toml  # noqa: F401

x, y, t = symbols()
R = sp.Rational
HERE = pathlib.Path(__file__).resolve().parent
CASES_DIR = HERE.parent / "cases"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="derive and check only, write nothing")
    ap.add_argument("--exmex", metavar="BIN", help="binary evaluating 'expr\\tt\\tx\\ty' lines with exmex")
    ap.add_argument("--no-selftest", action="store_true", help="skip the check that wrong data are rejected")
    ap.add_argument("--out", default=str(CASES_DIR), help="output directory (default verification/cases)")
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


if __name__ == "__main__":
    main()

"""Derivation, checks and scene files of the boundary-data cases (tresca_py.mms.boundary), the logic of
verification/mms/cases_boundary.py:

* the Dirichlet data u_D = u on every dirichlet side and the gap g_n = u.n on Gamma_C, printed and
  round-tripped like every other string;
* u_D equals u on Gamma_D (pointwise, space-time grid);
* the Tresca law on Gamma_C with u.n = g_n (tresca_py.mms.tresca_law); for the static case (b) the law of
  its one backward-Euler step from u0 = 0;
* a self-test: a flipped friction sign, a wrong bound and a wrong gap must each be caught.
"""
import argparse

import numpy as np
import sympy as sp

from tresca_py.common import CASES
from tresca_py.mms.blocks import lam
from tresca_py.mms.boundary import R, case_data_cep, case_data_front, case_data_stop, check_cep_symbolic
from tresca_py.mms.checks import check_derivatives, check_roundtrip
from tresca_py.mms.cli import derive_check_write, derive_each, scene_of
from tresca_py.mms.derive import CheckFailed, derive, printed, require
from tresca_py.mms.elasticity import side_normal_exact
from tresca_py.mms.scene_toml import scene_text
from tresca_py.mms.tresca_law import check_tresca_law, side_grid

BOUNDARY_CASES = [case_data_front, case_data_cep, case_data_stop]


def derive_data(case):
    """tresca_py.mms.derive.derive, plus the printed data strings u_D (per dirichlet side) and the gap."""
    d = derive(case)
    u = d["u"]
    for side, kind in case["kinds"].items():
        if kind == "dirichlet":
            d["sym"]["uD_%s_1" % side], d["sym"]["uD_%s_2" % side] = u[0], u[1]
        if kind == "contact":
            n = side_normal_exact(case["corners"], side)
            d["sym"]["gap_%s" % side] = sp.simplify(u[0] * n[0] + u[1] * n[1]) * case.get("gap_scale", 1)
    d["str"] = printed(case["name"], d["sym"])
    return d


def check_dirichlet(d, log):
    """u_D = u on Gamma_D (parsed strings, space-time grid); u0 = u(., 0) agrees with the data at t = 0 by
    construction (it is u(., 0))."""
    P = d["parsed"]
    u = [lam(P["u1"]), lam(P["u2"])]
    for side in [s for s, k in d["kinds"].items() if k == "dirichlet"]:
        PX, PY, TT, _, _ = side_grid(d["corners"], side, np.linspace(0, 1, 201), np.linspace(0, float(d["T"]), 21))
        err = max(np.max(np.abs(lam(P["uD_%s_%d" % (side, c + 1)])(PX, PY, TT) - u[c](PX, PY, TT)))
                  for c in range(2))
        require(err < 1e-13, "%s: u_D != u on %s (%.2e)" % (d["name"], side, err))
    log("u_D = u on Gamma_D                                                ok")


def check_contact_data(d, log):
    """Tresca's law with u.n = gap on every contact side (continuous in time for (a) and (c), the one
    backward-Euler step for (b)); the gap is nonzero where the case moves in time."""
    times = np.array([float(d["T"])]) if d["static"] else np.linspace(0, float(d["T"]), 401)
    for side in [s for s, k in d["kinds"].items() if k == "contact"]:
        gap = lam(d["parsed"]["gap_%s" % side])
        PX, PY, TT, _, _ = side_grid(d["corners"], side, np.linspace(0, 1, 201), times)
        require(np.max(np.abs(gap(PX, PY, TT))) > 0 or d["static"], "%s: the gap is zero" % d["name"])
        check_tresca_law(d, side, np.linspace(0, 1, 1001), times, gap=gap, log=log)


def run_checks(case, log=print):
    rng = np.random.default_rng(20261126)
    d = derive_data(case)
    check_roundtrip(d, rng, log)
    # the derivative checks, with the dirichlet sides (nonzero here) checked by check_dirichlet instead
    d2 = dict(d, kinds={k: ("neumann" if v == "neumann" else "other") for k, v in d["kinds"].items()})
    check_derivatives(d2, rng, log)
    check_dirichlet(d, log)
    check_contact_data(d, log)
    return d


def selftest():
    """Wrong data must be caught: flipped friction sign, bound 1% off, wrong gap. (Flipping the CEP
    slip flips its traction with it: that is a solution too, so (b)'s mutant is a wrong bound.)"""
    mutants = {
        "(a) slip along sigma_t": lambda: case_data_front(slip_sign=-1),
        "(a) g_a 1% too small": lambda: case_data_front(ga_scale=R(99, 100)),
        "(a) gap of the wrong size": lambda: case_data_front(gap_scale=R(11, 10)),
        "(b) g_a 1% too large (slip below the bound)": lambda: case_data_cep(ga_scale=R(101, 100)),
    }
    for what, make in mutants.items():
        try:
            run_checks(make(), log=lambda msg: None)
        except CheckFailed as err:
            print("   selftest: %-35s caught: %s" % (what, err))
            continue
        raise CheckFailed("selftest: mutant '%s' passed the checks" % what)


def data_scene_text(d):
    """The scene TOML of a derived boundary-data case: scene_toml's text plus the data keys after each
    part's kind line."""
    st = d["str"]
    out = []
    side = None
    for line in scene_text(d).split("\n"):
        out.append(line)
        if line.startswith("name = "):
            side = line.split('"')[1]
        if line.startswith("kind = ") and side is not None:
            kind = d["kinds"][side]
            if kind == "dirichlet":
                out.append('u = ["%s", "%s"]' % (st["uD_%s_1" % side], st["uD_%s_2" % side]))
            if kind == "contact":
                out.append('gap = "%s"' % st["gap_%s" % side])
    text = "\n".join(out).replace("GENERATED by verification/mms/derive.py",
                                  "GENERATED by verification/mms/cases_boundary.py")
    return text.replace("# Regenerate: .venv/bin/python verification/mms/derive.py",
                        "# Regenerate: cd verification/mms && ../../.venv/bin/python cases_boundary.py")


def main():
    ap = argparse.ArgumentParser(description="Manufactured cases with nonzero boundary data (mms_data_*).")
    ap.add_argument("--check", action="store_true", help="derive and check only, write nothing")
    ap.add_argument("--out", default=CASES, help="output directory (default verification/cases)")
    args = ap.parse_args()

    def derive_all():
        check_cep_symbolic(print)
        return [scene_of(d, data_scene_text(d)) for d in derive_each(BOUNDARY_CASES, run_checks)]
    derive_check_write(args, derive_all, selftest)

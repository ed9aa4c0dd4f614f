"""make verify: every verification study of tresca-cr, its requirements checked pass/fail.

Runs the release binary's `study` subcommand on the manufactured cases and on the paper's Example 5.1, the
independent Python solvers and the comparisons, and records every requirement of
:mod:`tresca_py.verify.requirements` in one :class:`~tresca_py.verify.harness.Harness`. Everything is written
under out/verify/ (tables and plots for reference/ staged in out/verify/reference/; `make reference`
publishes them; a --quick run writes under out/verify/quick/, never published); the summary is
out/verify/summary.md. Exit status 1 if any requirement fails.

    .venv/bin/python verification/run_all.py [--quick] [--only NAME ...] [--jobs N]

The studies run side by side on a pool of worker processes (:mod:`tresca_py.verify.pool`, 2 by default); the
requirement table, summary.md and the staged reference files are the same whatever the finishing order.
"""
import argparse
import os
import subprocess
import time

from tresca_py.common import BIN, PY
from tresca_py.verify import (adaptive, audits, checks, estimates, hertz, paper, pool, same_scheme, studies,
                               study_tests, unilateral)
from tresca_py.verify.harness import Harness, out_dir
from tresca_py.verify.pool import Study


#: the results files (patterns relative to out/verify/) each study writes: its EB1 audit's files
WRITES = {
    "be_exact": ("stick_to_slip_*.h5",),
    "estimates": ("differences/*",),
    "adaptive": ("adaptive/*",),
    "clients": ("verify_ex51.h5", "interrupted_runs/*"),
    "paraview": ("paraview_check/*",),
    "cross": ("cross_check/*",),
    "distributed": ("distributed/*",),
    "external": ("external/*",),
    "audit": ("audit/*",),
    "unilateral": ("unilateral/*",),
    "hertz": ("hertz/*.h5",),
    "same_scheme": ("same_scheme/*",),
}
#: studies that run with no other study beside them: `distributed` measures peak memory (D2) and runs
#: mpirun -n 3 on every core; `tests` (T1) runs verification/interrupted_runs.py into out/interrupted/, as
#: `clients` does, and mpirun -n 2
ALONE = {"distributed", "tests"}


def study_table(quick):
    """The studies by name, each a function of the harness, in the table's order (:class:`pool.Study`:
    ``writes``, the results files it writes under out/verify/, for its EB1 audit; ``alone``, run with no
    other study beside it)."""
    n = 4 if quick else 5
    fns = {
        "elastic": lambda hs: (
            studies.h_study(hs, "E1-rect", "verification/cases/elastic_rect.toml", "h_elastic_rect",
                            [(k, 1) for k in range(2, 7)], 1, 2,
                            "the CR solver shall converge on a smooth elasticity problem (rectangle)"),
            studies.h_study(hs, "E2-rotated", "verification/cases/elastic_rotated.toml", "h_elastic_rotated",
                            [(k, 1) for k in range(2, 7)], 1, 2,
                            "the CR solver shall converge on a smooth elasticity problem (rotated square)")),
        "front": lambda hs: studies.h_study(hs, "C1-front", "verification/cases/mms_front.toml", "h_mms_front",
                                            [(k, 64) for k in range(n)], 1, 2,
                                            "with a moving stick–slip front the solver shall converge in h",
                                            l2_required=False),
        "rotated": lambda hs: studies.h_study(hs, "C2-rotated", "verification/cases/mms_rotated.toml", "h_mms_rotated",
                                              [(k, 16) for k in range(n)], 1, 2,
                                              "with contact on a non-axis-aligned edge the solver shall converge in h",
                                              l2_required=False),
        "k": lambda hs: studies.k_study(hs, quick),
        "data": lambda hs: (
            studies.h_study(hs, "C3-data-front", "verification/cases/mms_data_front.toml", "h_mms_data_front",
                            [(k, 64) for k in range(n)], 1, 2,
                            "with nonzero Dirichlet data, an imposed normal displacement and a moving stick–slip "
                            "front the solver shall converge in h", l2_required=False),
            studies.h_study(hs, "C4-data-cep", "verification/cases/mms_data_cep.toml", "h_mms_data_cep",
                            [(k, 1) for k in range(n + 1)], 1, 2,
                            "on the near-incompressible Tresca solution of Chouly, Ern & Pignet (λ/μ = 10⁴, "
                            "Dirichlet data on three sides) the solver shall converge in h without locking"),
            studies.k_study(hs, quick, "mms_data_stop", "K3-data-stop")),
        "be_exact": studies.be_exact_study,
        "joint": lambda hs: studies.joint_study(hs, quick),
        "unilateral": lambda hs: unilateral.study(hs, quick),
        "hertz": lambda hs: hertz.study(hs, quick),
        "same_scheme": lambda hs: same_scheme.study(hs, quick),
        "paper": lambda hs: paper.paper_tables(hs, quick),
        "estimates": lambda hs: estimates.run(hs, quick),
        "adaptive": adaptive.study,
        "planner": lambda hs: checks.planner(hs, quick),
        "clients": checks.results_clients,
        "paraview": checks.paraview,
        "stability": checks.stability,
        "cross": lambda hs: checks.cross_check(hs, quick),
        "distributed": lambda hs: checks.distributed(hs, quick),
        "fuzz": lambda hs: checks.fuzz(hs, quick),
        "external": lambda hs: checks.external(hs, quick),
        "audit": lambda hs: audits.run_cases(hs, quick),
        "tests": study_tests.run,
    }
    return [Study(name, fn, alone=name in ALONE, writes=WRITES.get(name, ())) for name, fn in fns.items()]


def versions():
    version = subprocess.run([BIN, "--version"], capture_output=True, text=True).stdout.strip()
    pyv = subprocess.run([PY, "-c", "import skfem, dolfinx_solver, dolfinx, numpy, scipy, sympy; print('scikit-fem', "
                          "skfem.__version__, 'dolfinx', dolfinx.__version__, 'numpy', numpy.__version__, 'scipy', "
                          "scipy.__version__, 'sympy', sympy.__version__)"],
                         capture_output=True, text=True).stdout.strip()
    return f"{version}; {pyv}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller levels")
    ap.add_argument("--only", nargs="*", help="run only these studies")
    ap.add_argument("--jobs", type=int, default=pool.DEFAULT_JOBS,
                    help=f"studies run side by side (default {pool.DEFAULT_JOBS}; 1: one after the other)")
    args = ap.parse_args(argv)
    table = study_table(args.quick)
    unknown = sorted(set(args.only or []) - {s.name for s in table})
    if unknown:
        ap.error(f"unknown studies {', '.join(unknown)}; known: {', '.join(s.name for s in table)}")
    # a --quick run's tables are not the reference's: they go to out/verify/quick/, which `make reference` ignores
    hs = Harness(out=os.path.join(out_dir(), "quick") if args.quick else None)
    t0 = time.time()
    pool.run(hs, [s for s in table if not args.only or s.name in args.only], jobs=args.jobs)
    header = (f"Machine: {os.uname().nodename}, {os.cpu_count()} cores; total {time.time() - t0:.0f} s. "
              f"Versions: {versions()}.")
    return hs.report(header, partial=bool(args.only))

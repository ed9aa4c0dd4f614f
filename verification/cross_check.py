"""Cross-check of the three independent solvers of tresca-cr (issue 6): Rust, scikit-fem, dolfinx.
The logic is in tresca_py/verify/cross_check.py; this is its entry point.

    .venv/bin/python verification/cross_check.py [--quick] [--no-mpi] [--json out/cross_check.json]
    .venv/bin/python scripts/skfem_solve.py   SCENE -o sk.h5 -q --refine k [--steps N]
    .venv/bin/python scripts/dolfinx_solve.py SCENE -o dx.h5 -q --refine k [--steps N]
"""
import sys

from tresca_py.verify.cross_check import main

if __name__ == "__main__":
    sys.exit(main())

"""Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- DOLFINx 0.11 solver.

Usage:  python scripts/dolfinx_solve.py SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q]
        mpirun -n 2 python scripts/dolfinx_solve.py SCENE.toml -o OUT.h5      (same answer)

Independent of the Rust crate. The code (and the discrete problem it solves) is the package
tresca_py.dolfinx_cr; this file is its entry point.
"""
from tresca_py.dolfinx_cr.main import main

if __name__ == "__main__":
    main()

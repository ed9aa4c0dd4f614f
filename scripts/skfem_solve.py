"""Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- scikit-fem solver.

Usage:  python scripts/skfem_solve.py SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q]

Independent of the Rust crate. The code (and the discrete problem it solves) is the package
tresca_py.skfem_cr; this file is its entry point.
"""
from tresca_py.skfem_cr.main import main

if __name__ == "__main__":
    main()

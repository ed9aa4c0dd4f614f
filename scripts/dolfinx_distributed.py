"""Quasi-static Tresca friction with stabilised CR elements -- distributed DOLFINx 0.11 + PETSc/MUMPS solver.

Usage:  python scripts/dolfinx_distributed.py SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q]
        mpirun -n 4 python scripts/dolfinx_distributed.py SCENE.toml -o OUT.h5     (same answer)

The code, and how it distributes the problem, is the package tresca_py.dolfinx_cr.distributed; this file is
its entry point.
"""
from tresca_py.dolfinx_cr.distributed.main import main

if __name__ == "__main__":
    main()

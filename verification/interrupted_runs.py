"""Killed, stopped and resumed runs (one of them with unilateral contact) open in VTK, meshio and h5py
(O2-interrupted); the check is tresca_py/verify/interrupted.py.

    .venv/bin/python verification/interrupted_runs.py [--json OUT]
"""
import sys

from tresca_py.verify.interrupted import main

if __name__ == "__main__":
    sys.exit(main())

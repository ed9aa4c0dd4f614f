"""Stability of tresca-cr at the extremes (issue 7) -> reference/stability.md; exit status 1 on any FAIL.

    .venv/bin/python verification/stability.py [--json OUT] [--md FILE] [--only case_nu,...]

The cases are in the package tresca_py/verify/stability/.
"""
import sys

from tresca_py.verify.stability.main import main

if __name__ == "__main__":
    sys.exit(main())

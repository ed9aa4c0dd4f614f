"""Issue 15: `tresca-cr plan` checked against the truth -> reference/planner.md (PL1, PL2; with --costs the
CPU benchmark rows of `make bench`). The check is in tresca_py/verify/planner.py.

    .venv/bin/python verification/planner.py [--quick] [--costs] [--json OUT] [--md FILE] [--cases mms_front ...]
"""
import sys

from tresca_py.verify.planner import main

if __name__ == "__main__":
    sys.exit(main())

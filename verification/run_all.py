"""make verify: every requirement of verification/README.md checked pass/fail (tresca_py.verify.run_all).

    .venv/bin/python verification/run_all.py [--quick] [--only NAME ...] [--jobs N]
"""
import sys

from tresca_py.verify.run_all import main

if __name__ == "__main__":
    sys.exit(main())

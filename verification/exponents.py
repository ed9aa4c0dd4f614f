"""Issue 42: the singular exponents of the repository's scenes -> reference/exponents.md. The table is made by
tresca_py/verify/exponents.py.

    .venv/bin/python verification/exponents.py [--md FILE]
"""
import sys

from tresca_py.verify.exponents import main

if __name__ == "__main__":
    sys.exit(main())

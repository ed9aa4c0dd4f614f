"""Work-precision of tresca-cr on the manufactured cases (issue 7) -> reference/work_precision.{md,csv,png}.
The logic is in tresca_py/verify/work_precision.py; this is its entry point.

    .venv/bin/python verification/work_precision.py [--repeats 3] [--quick]
"""
import sys

from tresca_py.verify.work_precision import main

if __name__ == "__main__":
    sys.exit(main())

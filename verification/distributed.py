"""The distributed dolfinx + PETSc/MUMPS route (issue 16): agreement (D1) and memory spreading (D2).
The logic is in tresca_py/verify/distributed/; this is its entry point.

    .venv/bin/python verification/distributed.py [--memory] [--bin target/release/tresca-cr]
"""
import sys

from tresca_py.verify.distributed import main

if __name__ == "__main__":
    sys.exit(main())

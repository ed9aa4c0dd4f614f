"""Compare two ``tresca`` results files of the same scene: ``python scripts/compare.py A.h5 B.h5 [--tol 1e-8]``.

A thin entry point; the comparison lives in ``tresca_py.compare``."""
import sys

from tresca_py.compare import main

if __name__ == "__main__":
    sys.exit(main())

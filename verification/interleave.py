"""Compare two binaries by interleaved runs (tresca_py/bench/interleave.py); a benchmark tool.

    .venv/bin/python verification/interleave.py 21 OLD_BINARY NEW_BINARY -- \\
        run verification/cases/mms_stop.toml --refine 4 --steps 16 -q
"""
import sys

from tresca_py.bench.interleave import main

if __name__ == "__main__":
    sys.exit(main())

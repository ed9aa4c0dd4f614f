"""make bench: performance of tresca-cr (issue 7) -> reference/performance.md (+ reference/performance.csv).
The logic is in tresca_py/bench/report/; this is its entry point.

    .venv/bin/python verification/bench/report.py [--repeats 5] [--quick] [--max-refine-growth 7] [--no-python]
                                                  [--no-perf]
"""
import sys

from tresca_py.bench.report import main

if __name__ == "__main__":
    sys.exit(main())

"""The planner's cost model against the planned runs' measured walls (issue 42 item 5). Logic:
python/tresca_py/bench/costmodel.py.

    .venv/bin/python verification/bench/costmodel.py [--repeats 3] [--write reference/performance.md]
"""
from tresca_py.bench.costmodel import main

if __name__ == "__main__":
    main()

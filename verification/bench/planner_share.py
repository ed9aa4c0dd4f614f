"""The planner's CPU against the recommended plan's, binaries interleaved (issue 32). Logic:
python/tresca_py/bench/planner_share.py.

    .venv/bin/python verification/bench/planner_share.py [--bin OLD NEW] [--rounds 6] [--cases mms_rotated ...]
"""
from tresca_py.bench.planner_share import main

if __name__ == "__main__":
    main()

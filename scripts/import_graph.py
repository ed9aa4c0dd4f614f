"""Print the Rust crate's import graph findings: circles between files of `src/` and upward imports.

    .venv/bin/python scripts/import_graph.py [--src DIR] [--check]

With --check the exit status is 1 when there is a circle or an upward import (part of `make lint`).
"""
import sys

from tresca_py.imports import main

if __name__ == "__main__":
    sys.exit(main())

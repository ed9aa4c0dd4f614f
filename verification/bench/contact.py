"""Issue 40's speed section of `make bench`: Newton iterations per step on unilateral/Coulomb scenes over the
levels, and the cost of a unilateral Tresca run against the bilateral one. Logic: python/tresca_py/bench/contact.py.

    .venv/bin/python verification/bench/contact.py [--ratio-refine 8] [--max-refine 6] [--rounds 3] [--write FILE]
"""
from tresca_py.bench.contact import main

if __name__ == "__main__":
    main()

"""Pictures of a tresca-cr results file (matplotlib):
``.venv/bin/python scripts/render.py run.h5 [--times 0.25 0.5 1.0] [-o DIR] [--field vm|u] [--scale S]``.

A thin entry point; the pictures are drawn by ``tresca_py.render``."""
import sys

from tresca_py.render import main

if __name__ == "__main__":
    sys.exit(main())

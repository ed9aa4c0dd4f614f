"""Figures of ``tresca-cr adapt`` (meshes per level, error against DOF):
``.venv/bin/python scripts/adapt_plot.py meshes DIR -o OUT`` or ``... rates ADAPTIVE.csv UNIFORM.csv -o FIG.png``.

A thin entry point; the figures are drawn by ``tresca_py.adapt_plot``."""
import sys

from tresca_py.adapt_plot import main

if __name__ == "__main__":
    sys.exit(main())

"""Hertz in the external comparison (issue 40 item 5): the levels of a ``Scene`` whose meshes are new meshes.

Level L of load NAME is the Hertz study's mesh level L (:mod:`tresca_py.hertz.mesh`: every arc vertex on the
circle, h halving everywhere from level to level) with the displacement-driven load of the committed level-0
scene ``verification/cases/NAME.toml`` (the cut y = R pushed down by ``tresca_py.hertz.levels.DELTA``), written
into the run's work directory by :func:`tresca_py.hertz.levels.write_level`. The cut's Dirichlet data keeps the
body from floating: the study's P-driven form has a singular stiffness in y that GetFEM's and scikit-fem's
Newton do not handle. Level L's h is the nominal point spacing in the bulk, R·h_max·2^(−L), which halves exactly
for the Richardson ratio (the longest edge of each level's Delaunay triangulation, ≈ 1.7 h, halves only to ±5 %).
"""
from __future__ import annotations

from tresca_py.hertz.levels import DELTA, LOADS, variant, write_level


def level_scene(name, work, level):
    """(scene path, h) of level ``level`` of Hertz load ``name`` (``hertz_a10`` or ``hertz_a05``) in ``work``."""
    ld = next((ld for ld in LOADS if ld.name == name), None)
    if ld is None:
        raise ValueError(f"no Hertz load {name!r} ({', '.join(ld.name for ld in LOADS)})")
    path = write_level(str(work), variant(ld, P=None, delta=DELTA[name]), level, stem=f"{name}_l{level}")
    return path, ld.grading.h_max * ld.case.R * 0.5 ** level

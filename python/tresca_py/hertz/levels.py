"""The Hertz loads and their mesh levels: writes each level's mesh and scene, runs the release binary on it and
checks the result against Hertz (:mod:`tresca_py.hertz.extract`).

Two loads, a/R = 0.1 and 0.05: the force per unit length P = π E* a²/(4R) on the floating cylinder. Each
load's mesh size in the contact zone is h_c = (a/R)/4 · R · 2^(−level) within |p| ≤ 2a of the touching point,
graded up to R/8 (mesh.Grading); the contact part of the arc ends at x_c = 3a, beyond the zone. ``variant``
changes a load's case (the circle's gap instead of the polygon's, another ν) to measure what that changes.
"""
import dataclasses
import os
from dataclasses import dataclass

from tresca_py import results
from tresca_py.common import BIN, run
from tresca_py.hertz import extract, formulas
from tresca_py.hertz.mesh import Grading, quarter_disc, write_msh
from tresca_py.hertz.scene import Case, scene_text


@dataclass(frozen=True)
class Load:
    name: str
    case: Case
    grading: Grading


def load(name, a_over_R, R=1.0, E=1.0, nu=0.3):
    """The floating load whose Hertz half-width is a_over_R · R, and its grading."""
    return Load(name, Case(R=R, E=E, nu=nu, P=formulas.load_for(a_over_R, R, E, nu)),
                Grading(h_c=a_over_R / 4, d_c=2 * a_over_R, x_c=3 * a_over_R))


#: the loads of the study
LOADS = (load("hertz_a10", 0.1), load("hertz_a05", 0.05))
#: the approach δ of each load's cut in the displacement-driven form (``variant(ld, P=None, delta=…)``: the
#: committed level-0 scenes verification/cases/hertz_a*.toml and the external comparison), chosen for about the
#: load's a/R (measured: a/R = 0.099 and 0.047)
DELTA = {"hertz_a10": 0.015, "hertz_a05": 0.0042}


def write_level(directory, ld: Load, level, stem=None, header=""):
    """Write STEM.msh and STEM.toml (default stem NAME_lLEVEL) into ``directory``, the scene text after
    ``header``; the scene's path."""
    os.makedirs(directory, exist_ok=True)
    stem = stem or f"{ld.name}_l{level}"
    write_msh(os.path.join(directory, stem + ".msh"), *quarter_disc(ld.case.R, ld.grading, level))
    path = os.path.join(directory, stem + ".toml")
    title = f"Hertz: elastic cylinder on a rigid plane, {ld.name}, mesh level {level} (tresca_py.hertz)"
    with open(path, "w", encoding="utf-8") as f:
        f.write(header + scene_text(ld.case, stem + ".msh", title))
    return path


def run_level(directory, ld: Load, level, threads=1):
    """Run level ``level`` of load ``ld`` in ``directory``: (extract.Check, unknowns, command)."""
    scene = write_level(directory, ld, level)
    out = scene[:-5] + ".h5"
    cmd = [BIN, "run", scene, "-o", out, "--force", "--threads", str(threads)]
    run(cmd)
    c = extract.check(out, ld.case.R, ld.case.E, ld.case.nu)
    return c, int(results.read(out).attrs["n_dofs"]), cmd


def variant(ld: Load, **changes):
    """Load ``ld`` with its case's fields changed (``circle_gap=True``, ``nu=…``), named after the change."""
    tag = "_".join(f"{k}{v}" for k, v in changes.items() if v is not None)
    return Load(f"{ld.name}_{tag}", dataclasses.replace(ld.case, **changes), ld.grading)

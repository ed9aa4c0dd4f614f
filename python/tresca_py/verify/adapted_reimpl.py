"""The independent re-implementations (scikit-fem, dolfinx) on an adapted mesh: ``tresca-cr adapt … --out DIR
--gmsh`` writes each level's mesh as ``DIR/level_<k>.msh``; a copy of the scene pointing its ``[mesh] file``
at one of them is solved by ``tresca-cr run``, ``scripts/skfem_solve.py`` and ``scripts/dolfinx_solve.py``,
and the results files are compared (:func:`tresca_py.compare.compare_files`; the cross-check's 1e-8 bar).
"""
import os
import re

import numpy as np

from tresca_py import results
from tresca_py.common import BIN, PY, SCRIPTS, run
from tresca_py.compare import compare_files
from tresca_py.mesh import gmsh_mesh, match_points

CODES = ("skfem", "dolfinx")


def gmsh_matches_level(directory, k):
    """Check that ``level_<k>.msh`` holds the mesh of ``level_<k>.h5`` (same points, same triangles up to
    vertex numbering); returns the number of triangles. ValueError naming the mismatch."""
    g = gmsh_mesh(os.path.join(directory, f"level_{k}.msh"))
    h = results.read(os.path.join(directory, f"level_{k}.h5"), verify=False).mesh
    if len(g.triangles) != len(h.triangles) or len(g.points) != len(h.points):
        raise ValueError(f"level {k}: Gmsh file has {len(g.triangles)} triangles / {len(g.points)} points, "
                         f"the results file {len(h.triangles)} / {len(h.points)}")
    perm = match_points(h.points, g.points, what=f"level {k} points")   # g point i = h point perm[i]
    key = lambda tris: sorted(tuple(sorted(t)) for t in tris)          # noqa: E731
    if key(perm[g.triangles]) != key(h.triangles):
        raise ValueError(f"level {k}: the Gmsh file's triangles differ from the results file's")
    return len(g.triangles)


def level_count(directory):
    """Number of ``level_<k>.h5`` files in ``directory``."""
    return sum(1 for n in os.listdir(directory) if re.fullmatch(r"level_\d+\.h5", n))


def level_scene(scene, directory, k):
    """Write ``DIR/level_<k>.toml``: ``scene`` with its ``[mesh] file`` replaced by ``level_<k>.msh``."""
    with open(scene, encoding="utf-8") as f:
        text = f.read()
    new, n = re.subn(r'(?m)^file\s*=\s*".*"$', f'file = "level_{k}.msh"', text)
    if n != 1:
        raise ValueError(f"{scene}: expected one [mesh] file line, found {n}")
    path = os.path.join(directory, f"level_{k}.toml")
    with open(path, "w", encoding="utf-8") as f:
        f.write(new)
    return path


def solve_all(scene, work, codes=CODES):
    """Solve ``scene`` with the Rust binary and each of ``codes``; returns {code: results path}."""
    out = {"rust": os.path.join(work, "rust.h5")}
    run([BIN, "run", scene, "-q", "-o", out["rust"], "--force"])
    for code in codes:
        out[code] = os.path.join(work, f"{code}.h5")
        if os.path.exists(out[code]):
            os.remove(out[code])
        run([PY, os.path.join(SCRIPTS, f"{code}_solve.py"), scene, "-q", "-o", out[code], "--force"])
    return out


def worst(cmp):
    """The largest compared difference (du, dE, dσ, true-error differences) of a comparison."""
    return float(np.max([cmp["du"], cmp["dE"], cmp["dsig"], cmp["derr"]]))


def agreement(scene, directory, k, codes=CODES):
    """Rust, the ``codes`` and the adapt run's own ``level_<k>.h5`` on level k's Gmsh mesh: a dict pair →
    comparison (:func:`tresca_py.compare.compare_files`)."""
    path = level_scene(scene, directory, k)
    work = os.path.join(directory, f"level_{k}_runs")
    os.makedirs(work, exist_ok=True)
    files = solve_all(path, work, codes)
    pairs = {f"rust-{c}": compare_files(files["rust"], files[c]) for c in codes}
    pairs["adapt-rust"] = compare_files(os.path.join(directory, f"level_{k}.h5"), files["rust"])
    return pairs

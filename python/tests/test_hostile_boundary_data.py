"""Boundary data that cancel at t₀ by rounding (issue 43 §2): the Python solvers compare data with the rule of
``src/fem/lifting/consistency.rs`` (stated there once), so they accept and refuse the same scenes as the Rust
solver, the example of its module doc included."""
import os
import re
import subprocess

import numpy as np
import pytest

from tresca_py import scene_data
from tresca_py.common import BIN, ROOT
from tresca_py.mesh import build_mesh
from tresca_py.scene import SceneError, load_scene

CONSISTENCY = os.path.join(ROOT, "src/fem/lifting/consistency.rs")


def doc_scene():
    """The scene of src/fem/lifting/consistency.rs's module doc (a doctest there), read from it: GAP for the gap."""
    doc = "\n".join(ln[4:] for ln in open(CONSISTENCY).read().splitlines() if ln.startswith("//! "))
    return re.search(r'let text = r#"(.*?)"#;', doc, re.S).group(1)


def python_check(path):
    """scene_data.check_boundary_data on the scikit-fem discretisation of the scene at ``path``."""
    from tresca_py.skfem_cr.cr import Discretisation
    scene = load_scene(str(path))
    disc = Discretisation(scene, build_mesh(scene))          # runs the check itself
    b = np.flatnonzero(disc.is_boundary)
    scene_data.check_boundary_data(scene, disc.points, disc.edges[b], disc.part_of_edge[b])


@pytest.mark.parametrize("gap,accepted", [("(0.1 + t)^2 - 0.01 - 0.2*t - t^2", True), ("1e-17", False),
                                          ("(0.1 + t)^2 - 0.01 - 0.2*t - t^2 + 1e-15", False)])
def test_data_cancelling_by_rounding_are_judged_as_the_rust_solver_does(tmp_path, gap, accepted):
    """The system shall accept data that cancel to zero at t₀ by rounding (1.7e-18, within twice its rounding
    bound of 1.1e-17) and refuse a mismatch beyond it (1e-17 against u₀·n = 0), in Python as in Rust."""
    path = tmp_path / "doc.toml"
    path.write_text(doc_scene().replace("GAP", gap))
    rust = subprocess.run([BIN, "check", str(path)], capture_output=True, text=True, timeout=120)
    assert (rust.returncode == 0) == accepted, rust.stderr
    if accepted:
        python_check(path)
    else:
        with pytest.raises(SceneError, match="inconsistent boundary data"):
            python_check(path)


def test_the_tolerance_constants_are_the_rust_ones():
    """The system shall state the comparison's rule once: the Python constants are those of consistency.rs."""
    text = open(CONSISTENCY).read()
    for name in ("ROUNDING_ULPS", "ROUNDING_SAFETY"):
        rust = float(re.search(rf"pub const {name}: f64 = ([0-9.e+-]+);", text).group(1))
        assert getattr(scene_data, name) == rust, name
    assert re.search(r"\(1e-9 \* scale\)", text) and scene_data.REL_TOL == 1e-9

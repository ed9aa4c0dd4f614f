"""The re-implementations (scripts/skfem_solve.py, dolfinx_solve.py, dolfinx_distributed.py) on scene errors
(issue 34, section 6): each must refuse what the Rust solver refuses with one ``error:`` line naming the
problem as the Rust solver names it, a non-zero exit and no results file, and never show a traceback
(uncaught SceneError / RuntimeError / OSError)."""
import os
import subprocess
import sys

import pytest

from tresca_py import hostile
from tresca_py.common import SCRIPTS, case

SOLVERS = ["skfem_solve.py", "dolfinx_solve.py", "dolfinx_distributed.py"]


def elastic(**replace):
    """The text of verification/cases/elastic_rect.toml (no contact, one Dirichlet side) with lines replaced:
    key = the line's start, value = the new line."""
    lines = open(case("elastic_rect")).read().splitlines()
    for start, new in replace.items():
        lines = [new if line.startswith(start) else line for line in lines]
    return "\n".join(lines) + "\n"


# A Gmsh 4.1 unit square (two triangles) whose bottom edge is in two physical groups, "bottom" and "floor"
TWO_GROUPS_MSH = """$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
6
1 1 "bottom"
1 2 "right"
1 3 "top"
1 4 "left"
1 5 "floor"
2 10 "body"
$EndPhysicalNames
$Entities
0 5 1 0
1 0 0 0 1 0 0 1 1 0
2 1 0 0 1 1 0 1 2 0
3 0 1 0 1 1 0 1 3 0
4 0 0 0 0 1 0 1 4 0
5 0 0 0 1 0 0 1 5 0
10 0 0 0 1 1 0 1 10 0
$EndEntities
$Nodes
1 4 1 4
2 10 0 4
1
2
3
4
0 0 0
1 0 0
1 1 0
0 1 0
$EndNodes
$Elements
6 7 1 7
1 1 1 1
1 1 2
1 2 1 1
2 2 3
1 3 1 1
3 3 4
1 4 1 1
4 4 1
1 5 1 1
5 1 2
2 10 2 2
6 1 2 3
7 1 3 4
$EndElements
"""
TWO_GROUPS_SCENE = """[mesh]
file = "two.msh"
[material]
E = 100.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
[[boundary]]
name = "bottom"
kind = "neumann"
[[boundary]]
name = "right"
kind = "neumann"
[[boundary]]
name = "top"
kind = "neumann"
traction = ["0", "-1"]
[[boundary]]
name = "floor"
kind = "contact"
g_a = "1"
[time]
T = 1.0
steps = 2
"""

# (name, scene text, extra arguments, what the Rust solver says of the same scene, other files of the scene)
SCENES = [
    ("load NaN everywhere", elastic(**{"f = ": 'f = ["log(x - 5)", "0"]'}), [], "value NaN"),
    ("load NaN for t > 0.5", elastic(**{"f = ": 'f = ["log(0.6 - t)", "0"]'}), ["--steps", "4"], "value NaN"),
    ("traction Inf", elastic(**{'traction = ["2.88': 'traction = ["1/(x - 2)", "0"]'}), [], "value"),
    ("no Dirichlet part", elastic(**{'kind = "dirichlet"': 'kind = "neumann"\ntraction = ["0", "0"]'}), [],
     "no dirichlet part"),
    ("three mesh cells", elastic(**{"cells = ": "cells = [2, 2, 2]"}), [], "cells"),
    ("missing Gmsh mesh", elastic(**{"corners = ": 'file = "nope.msh"', "cells = ": "", "diagonal = ": ""}), [],
     "nope.msh"),
    ("Gmsh edge in two groups", TWO_GROUPS_SCENE, [], "in two parts", {"two.msh": TWO_GROUPS_MSH}),
]
SCENES = [s if len(s) == 5 else (*s, {}) for s in SCENES]


def write_scene(directory, text, files):
    for name, data in files.items():
        (directory / name).write_text(data)
    scene = directory / "scene.toml"
    scene.write_text(text)
    return scene
OUTPUTS = ["directory", "read-only directory"]


def solve(script, scene, out, *args, prefix=()):
    p = subprocess.run([*prefix, sys.executable, os.path.join(SCRIPTS, script), str(scene), "-o", str(out), "-q",
                        *args], capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def refused(rc, err):
    lines = [line for line in err.strip().splitlines() if line]
    assert rc != 0, err
    assert "Traceback" not in err, err
    assert len(lines) == 1 and lines[0].startswith("error: "), err


class TestSceneErrors:
    """The system shall refuse a scene the Rust solver refuses, in every re-implementation, with one error line
    and no results file."""

    @pytest.mark.parametrize("script", SOLVERS)
    @pytest.mark.parametrize("name,text,args,rust,files", SCENES, ids=[s[0] for s in SCENES])
    def test_scene(self, tmp_path, script, name, text, args, rust, files):
        scene = write_scene(tmp_path, text, files)
        out = tmp_path / "out.h5"
        rc, _, err = solve(script, scene, out, *args)
        refused(rc, err)
        assert rust.lower() in err.lower(), err
        assert sorted(os.listdir(tmp_path)) == sorted(["scene.toml", *files]), "the run left files behind"


class TestOutputErrors:
    """The system shall refuse an output path it cannot write, before solving, with one error line."""

    @pytest.mark.parametrize("script", SOLVERS)
    @pytest.mark.parametrize("where", OUTPUTS)
    def test_output(self, tmp_path, script, where):
        prefix = []
        out = tmp_path
        if where == "read-only directory":
            prefix = hostile.unprivileged()
            if prefix is None:
                pytest.skip("running as root without setpriv: permission bits cannot be tested")
            out = tmp_path / "ro"
            out.mkdir()
            out.chmod(0o555)
            out = out / "out.h5"
        refused(*solve(script, case("elastic_rect"), out, prefix=prefix)[::2])


RUST_PENDING: dict[str, str] = {}  # scenes the Rust solver still accepts (none since issue 34 section 3)


@pytest.mark.parametrize("name,text,args,rust,files", [
    pytest.param(*s, marks=pytest.mark.xfail(strict=False, reason=RUST_PENDING[s[0]])) if s[0] in RUST_PENDING
    else s for s in SCENES], ids=[s[0] for s in SCENES])
def test_rust_refuses_the_same_scene(tmp_path, name, text, args, rust, files):
    """The system shall (in its Rust solver, the reference for the cases above) refuse every scene of SCENES."""
    from tresca_py.common import BIN
    if not os.path.exists(BIN):
        pytest.skip("target/release/tresca-cr is not built")
    scene = write_scene(tmp_path, text, files)
    p = subprocess.run([BIN, "run", str(scene), "-o", str(tmp_path / "r.h5"), *args], capture_output=True,
                       text=True, timeout=120)
    assert p.returncode != 0 and rust.lower() in p.stderr.lower(), p.stderr
    assert not (tmp_path / "r.h5").exists()

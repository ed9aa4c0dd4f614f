"""Scene reading (tresca_py.scene): the schema's fixed-length arrays and unknown keys are refused as the Rust
reader refuses them, and the solver entry points turn bad input into a one-line `error:` message."""
import os
import sys

import pytest

from conftest import SCRIPTS, run
from tresca_py.errors import InputError
from tresca_py.scene import load_scene

BASE = """[mesh]
corners = {corners}
cells = {cells}
[material]
E = 1.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
[[boundary]]
name = "right"
kind = "neumann"
traction = {traction}
[[boundary]]
name = "top"
kind = "neumann"
[[boundary]]
name = "bottom"
kind = "neumann"
[time]
T = 1.0
steps = 2
{extra}"""
GOOD = dict(corners="[[0, 0], [1, 0], [1, 1], [0, 1]]", cells="[2, 2]", traction='["0", "0"]', extra="")
LONG = {
    "cells of three": dict(cells="[2, 2, 2]"),
    "corners of five": dict(corners="[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0.5]]"),
    "corner of three numbers": dict(corners="[[0, 0, 0], [1, 0], [1, 1], [0, 1]]"),
    "traction of three": dict(traction='["0", "0", "0"]'),
}
BAD = {
    "unknown key": dict(extra="[loads]\nf = ['0', '0']\ng = 1\n"),
    "unknown table": dict(extra="[load]\nf = ['0', '0']\n"),
    "grad of one row": dict(extra="[exact]\nu = ['0', '0']\ngrad = [['0', '0']]\n"),
}


def scene(tmp_path, **kw):
    path = tmp_path / "s.toml"
    path.write_text(BASE.format(**dict(GOOD, **kw)))
    return str(path)


@pytest.mark.parametrize("extra", ["", "[outputs]\nmax_slip = true\ntraction_at = [[0.5, 0.0]]\n",
                                   "[units]\nlength = 'm'\n"])
def test_the_system_shall_read_a_valid_scene_as_the_rust_solver_does(extra, tmp_path, rust_bin):
    p = scene(tmp_path, extra=extra)
    assert run([rust_bin, "check", p]).returncode == 0
    assert len(load_scene(p).times) == 3


@pytest.mark.parametrize("label", sorted(BAD))
def test_the_system_shall_refuse_what_the_rust_scene_reader_refuses(label, tmp_path, rust_bin):
    p = scene(tmp_path, **BAD[label])
    r = run([rust_bin, "check", p])
    assert r.returncode != 0, f"Rust accepts {label}"
    with pytest.raises(InputError):
        load_scene(p)


@pytest.mark.parametrize("label", sorted(LONG))
def test_the_system_shall_refuse_arrays_longer_than_the_schema(label, tmp_path):
    with pytest.raises(InputError, match="must be|expected"):
        load_scene(scene(tmp_path, **LONG[label]))


@pytest.mark.parametrize("label", sorted(LONG))
def test_the_rust_reader_shall_refuse_arrays_longer_than_the_schema(label, tmp_path, rust_bin):
    assert run([rust_bin, "check", scene(tmp_path, **LONG[label])]).returncode != 0


BAD_SCENES = {
    "unknown key": "[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\nfoo=1\n",
    "missing side": ("[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\n[material]\nE=1.0\nnu=0.3\n"
                     "[[boundary]]\nname='left'\nkind='dirichlet'\n[time]\nT=1.0\nsteps=2\n"),
    "bad expression": ("[mesh]\ncorners=[[0,0],[1,0],[1,1],[0,1]]\ncells=[2,2]\n[material]\nE=1.0\nnu=0.3\n"
                       "[[boundary]]\nname='left'\nkind='neumann'\ntraction=['q*x','0']\n[time]\nT=1.0\nsteps=2\n"),
    "missing file": None,
}


@pytest.mark.parametrize("solver", ["skfem", "dolfinx"])
@pytest.mark.parametrize("label", sorted(BAD_SCENES))
def test_the_system_shall_answer_bad_scenes_with_a_one_line_error(label, solver, tmp_path):
    p = tmp_path / "bad.toml"
    if BAD_SCENES[label] is not None:
        p.write_text(BAD_SCENES[label])
    r = run([sys.executable, os.path.join(SCRIPTS, f"{solver}_solve.py"), str(p), "-o", str(tmp_path / "bad.h5")])
    lines = r.stderr.strip().splitlines()
    assert r.returncode != 0
    assert lines and lines[-1].startswith("error:"), r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "bad.h5").exists()

"""Hostile outputs of the Python tools (issue 43, section 1): the ``-o`` of the solvers, the PNGs of render.py and
adapt_plot.py, under the rule of every output (``tresca_py.paths``: new_output, distinct, write_new). Every tool
runs as a subprocess with a timeout, so that one which opens a FIFO fails its test instead of hanging it (the
timeout bounds a hang; it is no requirement on time)."""
import os
import shutil
import subprocess
import sys

import pytest

from tresca_py import hostile, paths
from tresca_py.common import BIN, CASES, SCRIPTS

TIMEOUT = 120  # s: far beyond any of these tools' refusals or small runs


def tool(name, *args):
    """scripts/NAME with the venv's Python: (exit code, stdout, stderr); TimeoutExpired when it blocks."""
    p = subprocess.run([sys.executable, os.path.join(SCRIPTS, name), *map(str, args)], capture_output=True,
                       text=True, timeout=TIMEOUT)
    return p.returncode, p.stdout, p.stderr


def refused(rc, err, fragment):
    lines = [ln for ln in err.strip().splitlines() if ln]
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], err
    assert "Traceback" not in err


def victim(d, name="victim"):
    p = d / name
    p.write_text("V\n")
    return p


def lshape(d):
    """The L-shape scene of verification/cases (2 steps) with its Gmsh mesh, copied into ``d``: (scene, mesh)."""
    text = open(os.path.join(CASES, "lshape_adapt.toml")).read().replace("steps = 8", "steps = 2")
    (d / "lshape.toml").write_text(text)
    shutil.copy(os.path.join(CASES, "lshape.msh"), d / "lshape.msh")
    return d / "lshape.toml", d / "lshape.msh"


@pytest.mark.parametrize("target", ["scene", "mesh", "hard link of the scene"])
def test_solver_output_that_is_an_input_is_refused(tmp_path, target):
    """The system shall refuse a solver's -o that is its scene or mesh, compared by inode (a hard link counts),
    before any work, leaving both as they were."""
    scene, mesh = lshape(tmp_path)
    alias = tmp_path / "alias.toml"
    os.link(scene, alias)
    out = {"scene": scene, "mesh": mesh, "hard link of the scene": alias}[target]
    before = scene.read_bytes(), mesh.read_bytes()
    rc, _, err = tool("skfem_solve.py", scene, "-q", "-o", out)
    refused(rc, err, "overwrite the input")
    assert (scene.read_bytes(), mesh.read_bytes()) == before


def test_solver_output_links_fifos_and_existing_files(tmp_path):
    """The system shall refuse a solver's -o that is a symbolic link, a FIFO (at once, even with --force) or an
    existing file without --force, naming it and leaving it as it was."""
    scene, _ = lshape(tmp_path)
    v = victim(tmp_path)
    link = tmp_path / "link.h5"
    link.symlink_to(v)
    rc, _, err = tool("skfem_solve.py", scene, "-q", "-o", link)
    refused(rc, err, "symbolic link")
    assert link.is_symlink() and v.read_text() == "V\n"
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    rc, _, err = tool("skfem_solve.py", scene, "-q", "-o", fifo, "--force")
    refused(rc, err, "FIFO")
    mine = tmp_path / "mine.h5"
    mine.write_text("MINE")
    rc, _, err = tool("skfem_solve.py", scene, "-q", "-o", mine)
    refused(rc, err, "--force")
    assert mine.read_text() == "MINE"


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return hostile.rust_runs_or_skip(tmp_path_factory)


@pytest.fixture(scope="module")
def pictures(runs, tmp_path_factory):
    """The names render.py draws for the contact run (into a fresh directory)."""
    d = tmp_path_factory.mktemp("drawn")
    rc, _, err = tool("render.py", runs["contact"], "-o", d)
    assert rc == 0, err
    names = sorted(os.listdir(d))
    assert "energy.png" in names and any(n.startswith("contact_") for n in names), names
    return names


@pytest.mark.parametrize("which", ["first", "last"])
def test_render_never_draws_through_a_link(runs, pictures, tmp_path, which):
    """The system shall refuse render.py's pictures through a symbolic link planted under one of their names before
    drawing any, the link's target unchanged."""
    v = victim(tmp_path)
    out = tmp_path / "pictures"
    out.mkdir()
    name = pictures[0] if which == "first" else pictures[-1]
    (out / name).symlink_to(v)
    rc, _, err = tool("render.py", runs["contact"], "-o", out)
    refused(rc, err, "symbolic link")
    assert v.read_text() == "V\n" and os.listdir(out) == [name]


def test_render_fifo_and_existing_pictures(runs, pictures, tmp_path):
    """The system shall refuse a FIFO under a picture's name at once (never opened), and replace an existing
    picture only with --force."""
    out = tmp_path / "pictures"
    out.mkdir()
    os.mkfifo(out / pictures[0])
    rc, _, err = tool("render.py", runs["contact"], "-o", out)
    refused(rc, err, "FIFO")
    os.unlink(out / pictures[0])
    (out / pictures[-1]).write_text("MINE")
    rc, _, err = tool("render.py", runs["contact"], "-o", out)
    refused(rc, err, "--force")
    assert (out / pictures[-1]).read_text() == "MINE" and os.listdir(out) == [pictures[-1]]
    rc, _, err = tool("render.py", runs["contact"], "-o", out, "--force")
    assert rc == 0, err
    assert sorted(os.listdir(out)) == pictures and (out / pictures[-1]).read_bytes()[:4] == b"\x89PNG"


@pytest.fixture(scope="module")
def adapted(tmp_path_factory):
    """`tresca-cr adapt --levels 2` of Example 5.1: (level directory, its CSV)."""
    if not os.path.exists(BIN):
        pytest.skip("target/release/tresca-cr is not built (cargo build --release)")
    d = tmp_path_factory.mktemp("adapt")
    p = subprocess.run([BIN, "adapt", os.path.join(CASES, "paper_example_5_1.toml"), "--levels", "2", "--steps", "4",
                        "--out", d / "levels", "--csv", d / "a.csv"], capture_output=True, text=True, timeout=TIMEOUT)
    assert p.returncode == 0, p.stderr
    return d / "levels", d / "a.csv"


def test_adapt_plot_pictures_under_the_rule(adapted, tmp_path):
    """The system shall refuse adapt_plot.py's pictures through a planted symbolic link or onto a FIFO before
    drawing any, and a rates picture onto one of its own input tables."""
    levels, table = adapted
    v = victim(tmp_path)
    out = tmp_path / "meshes"
    out.mkdir()
    (out / "mesh_1.png").symlink_to(v)
    rc, _, err = tool("adapt_plot.py", "meshes", levels, "-o", out)
    refused(rc, err, "symbolic link")
    assert v.read_text() == "V\n" and os.listdir(out) == ["mesh_1.png"]
    fifo = tmp_path / "rates.png"
    os.mkfifo(fifo)
    rc, _, err = tool("adapt_plot.py", "rates", table, table, "-o", fifo)
    refused(rc, err, "FIFO")
    before = table.read_bytes()
    rc, _, err = tool("adapt_plot.py", "rates", table, table, "-o", table, "--force")
    refused(rc, err, "overwrite the input")
    assert table.read_bytes() == before


def test_the_rule_itself(tmp_path):
    """The system shall write a new file through a temporary created exclusively (a link planted under FILE.tmp is
    refused, its target unchanged), and compare outputs with inputs and each other by inode."""
    v = victim(tmp_path)
    out = tmp_path / "x.json"
    (tmp_path / "x.json.tmp").symlink_to(v)
    with pytest.raises(paths.PathError, match="symbolic link"):
        paths.write_new(str(out), lambda f: f.write(b"{}"), "summary")
    assert v.read_text() == "V\n" and not out.exists()
    os.unlink(tmp_path / "x.json.tmp")
    assert paths.write_new(str(out), lambda f: f.write(b"{}"), "summary") == str(out)
    with pytest.raises(paths.PathError, match="pass --force"):
        paths.write_new(str(out), lambda f: f.write(b"[]"), "summary")
    assert out.read_bytes() == b"{}" and not (tmp_path / "x.json.tmp").exists()
    os.link(v, tmp_path / "alias")
    with pytest.raises(paths.PathError, match="overwrite the input"):
        paths.distinct([(str(tmp_path / "alias"), "summary")], [(str(v), "scene")])
    with pytest.raises(paths.PathError, match="same file"):
        paths.distinct([(str(out), "summary"), (str(tmp_path / "." / "x.json"), "table")])

"""Hostile outputs of the writers issue 43 §1 left out (the rule of every output, ``tresca_py.paths``): the dolfinx
distributed solver's results file, parts and ParaView frames, and the screenshots of ``paraview_view.py``. Links,
devices and FIFOs are refused before any work, inputs are never overwritten, an existing file is replaced only
with --force. Every tool runs as a subprocess with a timeout, so that one which opens a FIFO fails its test
instead of hanging it (the timeout bounds a hang; it is no requirement on time)."""
import os
import shutil
import subprocess

import pytest

from tresca_py import hostile, results
from tresca_py.common import CASES, MPIRUN, PY, SCRIPTS
from tresca_py.xvfb import VirtualDisplay

TIMEOUT = 600  # s: far beyond a refusal or the one-step run below
SCENE = os.path.join(CASES, "mms_data_cep.toml")  # boundary data, one step, refine 0: the smallest real run
PVPYTHON = shutil.which("pvpython") and shutil.which("Xvfb")


def distributed(out, *extra):
    cmd = [MPIRUN, "-n", "1", PY, os.path.join(SCRIPTS, "dolfinx_distributed.py"), SCENE, "-o", str(out), "-q"]
    return subprocess.run(cmd + list(extra), capture_output=True, text=True, timeout=TIMEOUT)


def refused(p, fragment):
    assert p.returncode != 0 and fragment in p.stderr, p.stdout[-2000:] + p.stderr[-2000:]
    assert "Traceback" not in p.stderr, p.stderr[-2000:]


def victim_dir(tmp_path):
    d = tmp_path / "elsewhere"
    d.mkdir()
    for name in ("rank0.h5", "displacement.pvd"):
        (d / name).write_text("V\n")
    return d


@pytest.mark.parametrize("planted", ["run.h5.parts", "run_vtk"])
def test_distributed_never_writes_through_a_linked_directory(tmp_path, planted):
    """The system shall refuse a parts or frames directory of the distributed solver that is a symbolic link
    (its files would be written, and an earlier run's removed, wherever it points), before any work."""
    d = victim_dir(tmp_path)
    os.symlink(d, tmp_path / planted)
    p = distributed(tmp_path / "run.h5")
    refused(p, "symbolic link")
    assert sorted(os.listdir(d)) == ["displacement.pvd", "rank0.h5"]
    assert all((d / f).read_text() == "V\n" for f in os.listdir(d))
    assert not (tmp_path / "run.h5").exists()


def test_distributed_replaces_an_earlier_runs_files_only_with_force(tmp_path):
    """The system shall refuse the parts of an earlier run (its results file gone) without --force, and a part
    that is a link or has a second hard link even with it; with --force it replaces them, and its results file
    is read by ``tresca_py.results.read``."""
    out = tmp_path / "run.h5"
    assert distributed(out).returncode == 0
    os.remove(out)
    refused(distributed(out), "pass --force")
    part = tmp_path / "run.h5.parts" / "rank0.h5"
    keep = tmp_path / "keep.h5"
    os.link(part, keep)
    refused(distributed(out, "--force"), "2 hard links")
    os.remove(keep)
    p = distributed(out, "--force")
    assert p.returncode == 0, p.stderr[-2000:]
    r = results.read(str(out))
    assert r.completed == 2 and not os.path.lexists(str(out)[:-3] + ".tmp.h5")


def test_distributed_results_file_is_never_an_input(tmp_path):
    """The system shall refuse a results file that is the scene, even with --force."""
    scene = tmp_path / "scene.toml"
    shutil.copyfile(SCENE, scene)
    before = scene.read_bytes()
    cmd = [MPIRUN, "-n", "1", PY, os.path.join(SCRIPTS, "dolfinx_distributed.py"), str(scene), "-o", str(scene),
           "--force", "-q"]
    refused(subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT), "scene")
    assert scene.read_bytes() == before


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return hostile.rust_runs_or_skip(tmp_path_factory)


@pytest.fixture(scope="module")
def pv():
    with VirtualDisplay() as display:
        def run(*args):
            p = display.pvpython([os.path.join(SCRIPTS, "paraview_view.py"), *map(str, args)], timeout=TIMEOUT)
            return p.returncode, p.stdout, p.stderr
        yield run


@pytest.mark.skipif(not PVPYTHON, reason="pvpython or Xvfb missing (make paraview)")
class TestParaviewScreenshots:
    """The system shall write ParaView's screenshots under the rule of every output: never through a link, onto
    a FIFO or onto the results file, an existing picture replaced only with --force, refused before ParaView
    opens the run."""

    def test_links_fifos_and_inputs(self, pv, runs, tmp_path):
        v = tmp_path / "victim.png"
        v.write_text("V\n")
        link = tmp_path / "link.png"
        os.symlink(v, link)
        fifo = tmp_path / "fifo.png"
        os.mkfifo(fifo)
        run = runs["contact"]
        before = open(run, "rb").read()
        for out, force, fragment in [(link, "--force", "symbolic link"), (fifo, "--force", "FIFO"),
                                     (run, "--force", "would overwrite the input"), (v, None, "pass --force")]:
            rc, _, err = pv(run, "-o", out, *([force] if force else []))
            assert rc == 2 and fragment in err and "Traceback" not in err, (out, err)
        assert v.read_text() == "V\n" and open(run, "rb").read() == before
        frames = tmp_path / "frames"
        os.symlink(tmp_path / "elsewhere", frames)
        rc, _, err = pv(run, "--frames", frames)
        assert rc == 2 and "symbolic link" in err, err

    def test_force_replaces_a_picture(self, pv, runs, tmp_path):
        out = tmp_path / "v.png"
        out.write_text("old")
        rc, _, err = pv(runs["contact"], "-o", out, "--force")
        assert rc == 0, err
        assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and not (tmp_path / "v.tmp.png").exists()

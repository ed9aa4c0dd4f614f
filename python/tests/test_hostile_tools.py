"""The Python tools on hostile input (issue 34, section 6): check_results.py, render.py, compare.py and
paraview_view.py. Every hostile results file of ``tresca_py.hostile.RESULTS`` goes to every tool; the tools'
own arguments get the hostile values of ``ARGUMENTS``. Each must end in one ``error:`` line naming the problem
and a non-zero exit, never a traceback, a crash, a PASS or an exit 0 without its picture."""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from tresca_py import check, compare, hostile, render
from tresca_py.common import SCRIPTS
from tresca_py.xvfb import VirtualDisplay

IDS = [h[0] for h in hostile.RESULTS]
FILE_LEVEL = [h for h in hostile.RESULTS if h[3] == "file"]
PVPYTHON = shutil.which("pvpython") and shutil.which("Xvfb")


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return hostile.rust_runs_or_skip(tmp_path_factory)


def one_error_line(err, fragment=""):
    lines = [line for line in err.strip().splitlines() if line]
    assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], err
    assert "Traceback" not in err


def script(name, *args, prefix=(), timeout=120):
    """Run scripts/NAME with the venv's Python; (exit code, stdout, stderr)."""
    p = subprocess.run([*prefix, sys.executable, os.path.join(SCRIPTS, name), *map(str, args)],
                       capture_output=True, text=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def copied_pair(runs, d, name="copy"):
    """run.h5 copied with its run.xdmf into d under the name ``name``: unless that is the original's name, the
    sidecar references the original, not the copy."""
    for ext in (".h5", ".xdmf"):
        shutil.copy(os.path.splitext(runs["contact"])[0] + ext, os.path.join(d, name + ext))
    return os.path.join(d, name + ".h5")


def read_only_dir(d):
    ro = os.path.join(d, "ro")
    os.makedirs(ro)
    os.chmod(ro, 0o555)
    return ro


class TestCheckResults:
    """The system shall check the views of a valid results file, with or without a contact part, and refuse
    every other input with one error line."""

    @pytest.mark.parametrize("name,make,fragment,level", hostile.RESULTS, ids=IDS)
    def test_hostile_file(self, runs, tmp_path, capsys, name, make, fragment, level):
        assert check.main([make(runs["contact"], runs["plain"], str(tmp_path))]) == 2
        one_error_line(capsys.readouterr().err, fragment)

    @pytest.mark.parametrize("key", ["contact", "plain"])
    def test_valid_file(self, runs, capsys, key):
        assert check.main([runs[key]]) == 0, capsys.readouterr()

    def test_copied_pair(self, runs, tmp_path, capsys):
        assert check.main([copied_pair(runs, str(tmp_path))]) == 2
        one_error_line(capsys.readouterr().err, "belongs to another results file")

    @pytest.mark.parametrize("name,make,fragment", hostile.SIDECARS, ids=[h[0] for h in hostile.SIDECARS])
    def test_hostile_sidecar(self, runs, tmp_path, capsys, name, make, fragment):
        assert check.main([make(runs["contact"], str(tmp_path))]) == 2
        one_error_line(capsys.readouterr().err, fragment)

    def test_damaged_view(self, runs, tmp_path, capsys):
        """A valid /tresca with a damaged VTKHDF view is a mismatch found, not a crash."""
        p = copied_pair(runs, str(tmp_path), "contact")  # the same name: the sidecar still fits
        with h5py.File(p, "r+") as f:
            del f["VTKHDF/body/Types"]
        assert check.main([p]) == 1
        assert "Traceback" not in capsys.readouterr().err

    def test_entry_point(self, tmp_path):
        rc, out, err = script("check_results.py", tmp_path / "missing.h5")
        assert rc == 2
        one_error_line(err, "no such file")


class TestRender:
    """The system shall draw a valid results file, with or without a contact part, and refuse hostile files,
    scales, times and output directories before drawing."""

    @pytest.mark.parametrize("name,make,fragment,level", hostile.RESULTS, ids=IDS)
    def test_hostile_file(self, runs, tmp_path, capsys, name, make, fragment, level):
        out = tmp_path / "pictures"
        assert render.main([make(runs["contact"], runs["plain"], str(tmp_path)), "-o", str(out)]) == 2
        one_error_line(capsys.readouterr().err, fragment)
        assert not out.exists() or not os.listdir(out)

    @pytest.mark.parametrize("args", [["--scale", "nan"], ["--scale", "inf"], ["--scale", "-1"], ["--times", "nan"],
                                      ["--times", "0.5", "inf"], ["--field", "x"]])
    def test_hostile_argument(self, runs, tmp_path, capsys, args):
        with pytest.raises(SystemExit) as e:
            render.main([runs["contact"], "-o", str(tmp_path), *args])
        assert e.value.code == 2
        err = capsys.readouterr().err
        assert "error: argument" in err and "Traceback" not in err and not os.listdir(tmp_path)

    def test_output_onto_a_file(self, runs, tmp_path, capsys):
        f = tmp_path / "file.png"
        f.write_text("keep")
        assert render.main([runs["contact"], "-o", str(f)]) == 2
        one_error_line(capsys.readouterr().err, "not a directory")
        assert f.read_text() == "keep"

    def test_output_into_read_only_directory(self, runs, tmp_path):
        prefix = hostile.unprivileged()
        if prefix is None:
            pytest.skip("running as root without setpriv: permission bits cannot be tested")
        rc, out, err = script("render.py", runs["contact"], "-o", read_only_dir(str(tmp_path)), prefix=prefix)
        assert rc == 2
        one_error_line(err, "cannot create files")

    @pytest.mark.parametrize("key", ["contact", "plain"])
    def test_valid_file(self, runs, tmp_path, capsys, key):
        assert render.main([runs[key], "-o", str(tmp_path), "--scale", "2"]) == 0
        pngs = sorted(os.listdir(tmp_path))
        assert pngs and all(os.path.getsize(tmp_path / p) > 1000 for p in pngs)
        assert any(p.startswith("contact_") for p in pngs) == (key == "contact")


class TestCompare:
    """The system shall compare two valid results files and refuse a hostile one on either side; a NaN shall
    never PASS."""

    @pytest.mark.parametrize("side", [0, 1])
    @pytest.mark.parametrize("name,make,fragment,level", hostile.RESULTS, ids=IDS)
    def test_hostile_file(self, runs, tmp_path, capsys, name, make, fragment, level, side):
        pair = [runs["contact"], make(runs["contact"], runs["plain"], str(tmp_path))]
        assert compare.main(pair[::-1] if side else pair) == 2
        err = capsys.readouterr()
        one_error_line(err.err, fragment)
        assert "PASS" not in err.out

    def test_nan_fails(self, runs, tmp_path, capsys):
        nan = hostile.RESULTS[IDS.index("NaN in u")][1](runs["contact"], runs["plain"], str(tmp_path))
        assert compare.main([runs["contact"], nan]) != 0
        assert "PASS" not in capsys.readouterr().out
        with pytest.raises(compare.CompareError, match="NaN"):
            compare.compare_files(runs["contact"], nan)

    def test_nan_difference_fails(self):
        """Python's max(0.0, nan) is 0.0: the worst difference must propagate NaN instead."""
        assert np.isnan(float(np.maximum(0.0, np.nan)))

    @pytest.mark.parametrize("args", [["--tol", "nan"], ["--tol", "-1"], ["--err-floor", "inf"]])
    def test_hostile_tolerance(self, runs, capsys, args):
        assert compare.main([runs["contact"], runs["contact"], *args]) == 2
        one_error_line(capsys.readouterr().err, "must be finite")

    def test_different_meshes(self, runs, capsys):
        assert compare.main([runs["contact"], runs["plain"]]) == 2
        one_error_line(capsys.readouterr().err)

    def test_same_file_passes(self, runs, capsys):
        assert compare.main([runs["contact"], runs["contact"], "--quiet"]) == 0
        assert "PASS" in capsys.readouterr().out

    def test_entry_point(self, runs, tmp_path):
        rc, out, err = script("compare.py", runs["contact"], tmp_path)
        assert rc == 2
        one_error_line(err, "is a directory")


@pytest.fixture(scope="class")
def pv():
    """pvpython scripts/paraview_view.py ARGS -> (exit code, stdout, stderr) on a virtual display of our own,
    repeated on a new server (up to `tresca_py.xvfb.ATTEMPTS` runs) if pvpython lost its X server."""
    with VirtualDisplay() as display:
        def run(*args, prefix=()):
            p = display.pvpython([os.path.join(SCRIPTS, "paraview_view.py"), *args], prefix=prefix, timeout=300)
            return p.returncode, p.stdout, p.stderr
        yield run


@pytest.mark.skipif(not PVPYTHON, reason="pvpython or Xvfb missing (make paraview)")
class TestParaviewView:
    """The system shall show a valid run in ParaView, with or without a contact part, and refuse every hostile
    input before ParaView opens it, with one error line and a non-zero exit."""

    @pytest.mark.parametrize("name,make,fragment,level", FILE_LEVEL, ids=[h[0] for h in FILE_LEVEL])
    def test_hostile_file(self, pv, runs, tmp_path, name, make, fragment, level):
        rc, out, err = pv(make(runs["contact"], runs["plain"], str(tmp_path)), "-o", tmp_path / "v.png")
        assert rc == 2
        one_error_line(err, fragment)

    def test_foreign_hdf5(self, pv, runs, tmp_path):
        foreign = hostile.RESULTS[IDS.index("foreign HDF5")][1](runs["contact"], runs["plain"], str(tmp_path))
        rc, out, err = pv(foreign)
        assert rc == 2
        one_error_line(err, "sidecar")

    @pytest.mark.parametrize("name,make,fragment", hostile.SIDECARS, ids=[h[0] for h in hostile.SIDECARS])
    def test_hostile_sidecar(self, pv, runs, tmp_path, name, make, fragment):
        rc, out, err = pv(make(runs["contact"], str(tmp_path)), "-o", tmp_path / "v.png")
        assert rc == 2
        one_error_line(err, fragment)

    def test_vtkhdf_on_5_11(self, pv, runs, tmp_path):
        """ParaView 5.11 cannot read temporal VTKHDF collections: said, exit 1, no picture."""
        rc, out, err = pv(runs["contact"], "--vtkhdf", "-o", tmp_path / "v.png")
        if rc == 0:
            pytest.skip("this ParaView reads temporal VTKHDF (5.13 or newer)")
        assert rc == 1
        one_error_line(err, "cannot read temporal VTKHDF")

    def test_without_pvpython(self, runs, tmp_path):
        """Run by the venv's Python, which has no ParaView: one line saying what to run instead."""
        rc, out, err = script("paraview_view.py", runs["contact"], "-o", tmp_path / "v.png")
        assert rc == 2
        one_error_line(err, "pvpython")

    @pytest.mark.parametrize("opened", ["copy.h5", "copy.xdmf"])
    def test_copied_pair(self, pv, runs, tmp_path, opened):
        copied_pair(runs, str(tmp_path))
        rc, out, err = pv(tmp_path / opened, "-o", tmp_path / "v.png")
        assert rc == 2
        one_error_line(err, "belongs to another results file")
        assert not (tmp_path / "v.png").exists()

    @pytest.mark.parametrize("args,fragment", [(["--size", "0", "0"], "--size"), (["--size", "-5", "100"], "--size"),
                                               (["--scale", "nan"], "--scale"), (["--scale", "inf"], "--scale"),
                                               (["--time", "nan"], "--time")])
    def test_hostile_argument(self, pv, runs, tmp_path, args, fragment):
        rc, out, err = pv(runs["contact"], "-o", tmp_path / "v.png", *args)
        assert rc == 2 and f"error: argument {fragment}" in err and "Traceback" not in err
        assert not (tmp_path / "v.png").exists()

    def test_output_onto_a_directory(self, pv, runs, tmp_path):
        rc, out, err = pv(runs["contact"], "-o", tmp_path)
        assert rc == 2
        one_error_line(err, "is a directory")

    def test_frames_onto_a_file(self, pv, runs, tmp_path):
        f = tmp_path / "frames"
        f.write_text("keep")
        rc, out, err = pv(runs["contact"], "--frames", f)
        assert rc == 2
        one_error_line(err, "is not a directory")
        assert f.read_text() == "keep"

    def test_output_into_read_only_directory(self, pv, runs, tmp_path):
        prefix = hostile.unprivileged()
        if prefix is None:
            pytest.skip("running as root without setpriv: permission bits cannot be tested")
        rc, out, err = pv(runs["contact"], "-o", os.path.join(read_only_dir(str(tmp_path)), "v.png"),
                                prefix=prefix)
        assert rc == 2
        one_error_line(err, "cannot create files")

    @pytest.mark.parametrize("key", ["contact", "plain"])
    def test_valid_file(self, pv, runs, tmp_path, key):
        """A run without a contact part once crashed pvpython (SIGSEGV in vtkExtractBlockUsingDataAssembly)."""
        rc, out, err = pv(runs[key], "-o", tmp_path / "v.png")
        assert rc == 0, err
        assert os.path.getsize(tmp_path / "v.png") > 1000



def test_reference_of_an_h5py_group(runs):
    """The system shall give the same expected view arrays from an open h5py group (as
    verification/paraview_check.py calls check_results.reference) as from the validated results."""
    from tresca_py import results
    r = results.read(runs["contact"])
    with h5py.File(runs["contact"]) as f:
        a = check.reference(f["tresca"], 3)
    b = check.reference(r)
    for x, y in zip(a, b, strict=True):
        assert np.array_equal(x, y[:3])

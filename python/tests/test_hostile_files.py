"""The Python tools on damaged or foreign files (issue 43, section 6): malformed audit series, declared sizes
beyond the file, virtual datasets without their source, NaN in adapt's tables, a user block before the
superblock, and exact zeros on the energy picture's log axis."""
import os
import re
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from tresca_py import audit, check, hostile, paths, render, results, vtkhdf_layout
from tresca_py.common import SCRIPTS


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return hostile.rust_runs_or_skip(tmp_path_factory)


def copy(good, tmp_path, name):
    """A copy of ``good`` (with its sidecar, which names the file: same name) in ``tmp_path/name``."""
    d = tmp_path / name
    d.mkdir()
    name = os.path.basename(good)
    p = d / name
    shutil.copyfile(good, p)
    side = os.path.splitext(good)[0] + ".xdmf"
    if os.path.exists(side):
        shutil.copyfile(side, d / (os.path.splitext(name)[0] + ".xdmf"))
    return str(p)


def damage_audit(path, how):
    with h5py.File(path, "r+") as f:
        g = f["tresca/steps"]
        n = g["balance_residual"].shape[0]
        del g["balance_residual"]
        if how == "short":
            g["balance_residual"] = np.zeros(1)
        elif how == "2-D":
            g["balance_residual"] = np.zeros((n, 2))
        elif how == "strings":
            g["balance_residual"] = np.array([b"x"] * n)
        else:
            g.create_group("balance_residual")


@pytest.mark.parametrize("how", ["short", "2-D", "strings", "a group"])
def test_malformed_audit_series_are_an_error_not_a_traceback(runs, tmp_path, how, capsys):
    """The system shall refuse an audit series that is short, 2-D, of strings or a group with one error naming
    the series and exit code 2, never a traceback."""
    p = copy(runs["contact"], tmp_path, "audit.h5")
    damage_audit(p, how)
    with pytest.raises(results.ResultsError, match="balance_residual"):
        audit.read(p, results.read(p).completed)
    assert check.main([p]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "balance_residual" in err and "Traceback" not in err


def test_a_declared_point_count_beyond_the_file_is_refused_before_reading(runs, tmp_path):
    """The system shall refuse a /VTKHDF block that declares 10⁹ points in a small file, before a reader
    allocates them."""
    p = copy(runs["contact"], tmp_path, "points.h5")
    with h5py.File(p, "r+") as f:
        f["VTKHDF/body/NumberOfPoints"][0] = 10**9
    with pytest.raises(results.ResultsError, match="NumberOfPoints declares 1000000000"):
        vtkhdf_layout.declared_sizes(p)
    vtkhdf_layout.declared_sizes(runs["contact"])  # the good file passes


def test_a_virtual_dataset_without_its_source_is_refused(runs, tmp_path):
    """The system shall refuse a results series that is a virtual dataset whose source file is missing (HDF5
    reads it as zeros), and read the same series when its source is there."""
    src = tmp_path / "source.h5"
    p = copy(runs["contact"], tmp_path, "virtual.h5")
    with h5py.File(p, "r+") as f:
        u = f["tresca/u"][()]
        with h5py.File(src, "w") as s:
            s["u"] = u
        del f["tresca/u"]
        layout = h5py.VirtualLayout(shape=u.shape, dtype=u.dtype)
        layout[...] = h5py.VirtualSource(str(src), "u", shape=u.shape)
        f["tresca"].create_virtual_dataset("u", layout)
    assert np.array_equal(results.read(p).u, u[:results.read(p).completed])
    os.remove(src)
    with pytest.raises(results.ResultsError, match="virtual dataset whose source .*source.h5:u is missing"):
        results.read(p)


def test_adapt_plot_refuses_nan(tmp_path):
    """The system shall refuse a NaN in adapt's table naming the line and column, not draw it."""
    head = "level,unknowns,estimator,error\n"
    good = tmp_path / "uniform.csv"
    good.write_text(head + "0,100,0.1,0.2\n1,400,0.05,0.1\n")
    bad = tmp_path / "adaptive.csv"
    bad.write_text(head + "0,100,0.1,0.2\n1,300,nan,0.1\n")
    out = tmp_path / "rates.png"
    p = subprocess.run([sys.executable, os.path.join(SCRIPTS, "adapt_plot.py"), "rates", str(bad), str(good), "-o",
                        str(out)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and "line 3, column estimator = 'nan'" in p.stderr, p.stderr
    assert "Traceback" not in p.stderr and not out.exists()


def test_a_user_block_is_not_called_truncated(tmp_path):
    """The system shall read an HDF5 file whose superblock follows a user block, and still call a cut copy of
    it truncated."""
    p = tmp_path / "ub.h5"
    with h5py.File(p, "w", userblock_size=512) as f:
        f["a"] = np.arange(100.0)
    assert paths.hdf5_file(str(p)) == str(p)
    cut = tmp_path / "cut.h5"
    cut.write_bytes(p.read_bytes()[:-100])
    with pytest.raises(paths.PathError, match="truncated"):
        paths.hdf5_file(str(cut))


def test_energy_picture_plots_exact_zeros_as_zeros(runs):
    """The system shall keep the energy picture's log axis to the nonzero residuals: exact zeros are marked
    apart, not drawn at 1e-300, which made the axis span 300 decades."""
    d = render.load(runs["contact"])
    r = np.abs(d["audit"]["balance_residual"][1:])
    r[::2] = 0.0
    d["audit"]["balance_residual"][1:] = r
    a2 = render.energy_figure(d).axes[1]
    low, high = a2.get_ylim()
    assert low >= r[r > 0].min() / 100, (low, high)
    assert any("exactly 0" in t.get_text() for t in a2.get_legend().get_texts())


def lengthen(path, names):
    """Each dataset ``names`` under every block's ``VTKHDF/<block>/Steps`` made 12 times as long (the added
    values grow on from its last one)."""
    with h5py.File(path, "r+") as f:
        for b, _ in vtkhdf_layout.blocks(f):
            st = f[f"VTKHDF/{b}/Steps"]
            for k in names(st):
                a = st[k][()]
                del st[k]
                st.create_dataset(k, data=np.concatenate([a, a[-1] + np.arange(1, 11 * len(a) + 1) * max(1, a[-1])]))


@pytest.mark.parametrize("how", ["values", "every_array", "offset", "nsteps"])
def test_vtkhdf_steps_beyond_nsteps_are_refused_before_vtk_reads(runs, tmp_path, how):
    """The system shall refuse a VTKHDF view whose Steps/Values is longer than the other Steps arrays, whose
    Steps arrays (all longer than NSteps, as a stopped run leaves them) hold offsets past their datasets, whose
    NSteps exceeds them, or whose data offset sends a step past its dataset, naming the dataset, with a
    non-zero exit: VTK's reader corrupted its heap on the first two (SIGSEGV or glibc's abort)."""
    p = copy(runs["contact"], tmp_path, f"{how}.h5")
    if how == "values":
        lengthen(p, lambda st: ["Values"])
    elif how == "every_array":
        lengthen(p, lambda st: [k for k in st if isinstance(st[k], h5py.Dataset)]
                 + [f"{g}/{k}" for g in ("PointDataOffsets", "CellDataOffsets") for k in st[g]])
    with h5py.File(p, "r+") as f:
        if how == "offset":
            f["VTKHDF/body/Steps/PointDataOffsets/displacement"][-1] = 10**6
        elif how == "nsteps":
            f["VTKHDF/body/Steps"].attrs["NSteps"] = np.int64(10**6)
    want = {"values": r"Steps/\S+ has shape \(\d+,\), fewer than the \d+ values of Steps/Values",
            "every_array": r"(sends step \d+ to rows|a step's parts run past)",
            "offset": r"PointDataOffsets/displacement sends step \d+ to rows up to 1000",
            "nsteps": r"Steps/Values holds \d+ values, fewer than NSteps = 1000000"}[how]
    with pytest.raises(results.ResultsError, match=want):
        vtkhdf_layout.validate(p)
    vtkhdf_layout.validate(runs["contact"])  # the good file passes
    c = subprocess.run([sys.executable, os.path.join(SCRIPTS, "check_results.py"), p], capture_output=True,
                       text=True, timeout=300)
    assert c.returncode == 1, (c.returncode, c.stdout[-2000:], c.stderr[-2000:])
    assert re.search(want, c.stdout) and "Traceback" not in c.stdout + c.stderr, c.stdout[-2000:]

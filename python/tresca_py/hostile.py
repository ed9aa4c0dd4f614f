"""Hostile results files, made from a good one: the corpus the tools' tests (``python/tests/test_hostile_*.py``,
``test_results.py``) feed to every reader, and that a fuzz run can reuse.

``RESULTS``: (name, make, what the refusal says, level). ``make(good, plain, d)`` writes a hostile file under
directory ``d`` from ``good`` (a results file with a contact part) or ``plain`` (one without) and returns its
path. ``level`` "file": caught by the standard-library checks (``tresca_py.paths``, what pvpython runs too);
"data": caught by reading the HDF5 content (``tresca_py.results.read``).
"""
import os
import shutil

import numpy as np


def _copy(src, d, name):
    p = os.path.join(d, name)
    shutil.copy(src, p)
    return p


def _edit(src, d, name, fn):
    """A copy of ``src`` changed by fn(tresca group) through h5py."""
    import h5py
    p = _copy(src, d, name)
    with h5py.File(p, "r+") as f:
        fn(f["tresca"])
    return p


def _write(d, name, data):
    p = os.path.join(d, name)
    with open(p, "wb") as f:
        f.write(data)
    return p


def _set(name, value):
    def fn(g):
        a = g[name][()]
        a[(min(2, len(a) - 1),) + (0,) * (a.ndim - 1)] = value
        g[name][...] = a
    return fn


def _attr(name, value, where=""):
    def fn(g):
        (g[where] if where else g).attrs[name] = value
    return fn


def _delete(name, where=None):
    def fn(g):
        if where is None:
            del g[name]
        else:
            del (g[where] if where else g).attrs[name]
    return fn


def _replace(name, make):
    def fn(g):
        a = g[name][()]
        del g[name]
        g.create_dataset(name, data=make(a))
    return fn


def _foreign(d, name):
    import h5py
    p = os.path.join(d, name)
    with h5py.File(p, "w") as f:
        f["data"] = np.arange(10.0)
    return p


def _tresca_dataset(d, name):
    import h5py
    p = os.path.join(d, name)
    with h5py.File(p, "w") as f:
        f["tresca"] = np.zeros(3)
    return p


def _fifo(d, name):
    p = os.path.join(d, name)
    os.mkfifo(p)
    return p


def _link(target):
    def make(good, plain, d):
        p = os.path.join(d, f"link{len(target)}.h5")
        os.symlink(target, p)
        return p
    return make


def _truncate(n):
    def make(good, plain, d):
        with open(good, "rb") as f:
            return _write(d, f"trunc{n}.h5", f.read(n if n > 0 else os.path.getsize(good) + n))
    return make


def _flip_checksummed(g):
    """A finite change of one value of u in step 1: only the step checksum can tell."""
    a = g["u"][()]
    a[1, 0, 0] = a[1, 0, 0] * (1 + 1e-9) + 1e-300
    g["u"][...] = a


def _side_not_edge(g):
    e = g["mesh/edges"][()]
    e[0, 1] = e[0, 0]  # a degenerate edge in place of a triangle side
    g["mesh/edges"][...] = e


RESULTS = (
    ("missing", lambda good, plain, d: os.path.join(d, "missing.h5"), "no such file", "file"),
    ("empty", lambda good, plain, d: _write(d, "empty.h5", b""), "is empty", "file"),
    ("directory", lambda good, plain, d: os.makedirs(os.path.join(d, "dir.h5")) or os.path.join(d, "dir.h5"),
     "is a directory", "file"),
    ("text", lambda good, plain, d: _write(d, "text.h5", b"time,u\n0,1\n"), "not an HDF5 file", "file"),
    ("binary junk", lambda good, plain, d: _write(d, "junk.h5", bytes(range(256)) * 8), "not an HDF5 file", "file"),
    ("FIFO", lambda good, plain, d: _fifo(d, "fifo.h5"), "not a regular file", "file"),
    ("link to /dev/zero", _link("/dev/zero"), "not a regular file", "file"),
    ("dangling link", _link("/nonexistent/run.h5"), "no such file", "file"),
    ("truncated to half", lambda good, plain, d: _truncate(os.path.getsize(good) // 2)(good, plain, d),
     "truncated", "file"),
    ("truncated by 1 byte", _truncate(-1), "truncated", "file"),
    ("truncated in the superblock", _truncate(40), "truncated", "file"),
    ("foreign HDF5", lambda good, plain, d: _foreign(d, "foreign.h5"), "no /tresca group", "data"),
    ("/tresca is a dataset", lambda good, plain, d: _tresca_dataset(d, "tds.h5"), "no /tresca group", "data"),
    ("NaN in u", lambda good, plain, d: _edit(good, d, "nan_u.h5", _set("u", np.nan)), "tresca/u holds 1 NaN", "data"),
    ("Inf in u (no contact)", lambda good, plain, d: _edit(plain, d, "inf_u.h5", _set("u", np.inf)),
     "tresca/u holds 1 NaN/Inf", "data"),
    ("NaN in energy", lambda good, plain, d: _edit(good, d, "nan_e.h5", _set("energy", np.nan)), "tresca/energy",
     "data"),
    ("Inf in sigma_t", lambda good, plain, d: _edit(good, d, "inf_s.h5", _set("contact/sigma_t", -np.inf)),
     "tresca/contact/sigma_t holds", "data"),
    ("NaN in an error norm", lambda good, plain, d: _edit(good, d, "nan_err.h5", _set("errors/h1", np.nan)),
     "tresca/errors/h1", "data"),
    ("NaN in a point", lambda good, plain, d: _edit(good, d, "nan_p.h5", _set("mesh/points", np.nan)),
     "tresca/mesh/points holds", "data"),
    ("contact part deleted", lambda good, plain, d: _edit(good, d, "no_contact.h5", _delete("contact")),
     "contact part of the run is missing", "data"),
    ("contact/mu deleted", lambda good, plain, d: _edit(good, d, "no_mu.h5", _delete("contact/mu")),
     "tresca/contact/mu is missing", "data"),
    ("u deleted", lambda good, plain, d: _edit(good, d, "no_u.h5", _delete("u")), "tresca/u is missing", "data"),
    ("status unknown", lambda good, plain, d: _edit(good, d, "st.h5", _attr("status", "exploded")), "unknown status",
     "data"),
    ("status missing", lambda good, plain, d: _edit(good, d, "st0.h5", _delete("status", "")),
     "attribute status", "data"),
    ("status a number", lambda good, plain, d: _edit(good, d, "st1.h5", _attr("status", 7)), "not of type str",
     "data"),
    ("completed beyond the rows", lambda good, plain, d: _edit(good, d, "c1.h5", _attr("completed", 10**6, "steps")),
     "marked complete", "data"),
    ("completed 0", lambda good, plain, d: _edit(good, d, "c0.h5", _attr("completed", 0, "steps")),
     "no committed step", "data"),
    ("completed missing", lambda good, plain, d: _edit(good, d, "c2.h5", _delete("completed", "steps")),
     "completed of tresca/steps is missing", "data"),
    ("steps attribute raised", lambda good, plain, d: _edit(good, d, "n.h5", _attr("steps", 10**6)),
     "status 'completed' but", "data"),
    ("u with 3 components", lambda good, plain, d: _edit(
        good, d, "u3.h5", _replace("u", lambda a: np.concatenate([a, a[..., :1]], axis=2))), "tresca/u has shape",
     "data"),
    ("u of integers", lambda good, plain, d: _edit(good, d, "ui.h5", _replace("u", lambda a: a.astype(np.int64))),
     "tresca/u holds int64", "data"),
    ("triangle index out of range", lambda good, plain, d: _edit(good, d, "ti.h5", _set("mesh/triangles", 10**6)),
     "indices outside", "data"),
    ("triangle side not an edge", lambda good, plain, d: _edit(good, d, "se.h5", _side_not_edge), "is not an edge",
     "data"),
    ("times not increasing", lambda good, plain, d: _edit(good, d, "ti2.h5", _set("times", -1.0)), "not increasing",
     "data"),
    ("stick/slip state 7", lambda good, plain, d: _edit(good, d, "s7.h5", _set("contact/state", 7)),
     "state holds values", "data"),
    ("contact edge twice", lambda good, plain, d: _edit(
        good, d, "ce.h5", _replace("contact/edges", lambda a: np.r_[a[:1], a[:1], a[2:]])), "lists an edge twice",
     "data"),
    ("E is NaN", lambda good, plain, d: _edit(good, d, "enan.h5", _attr("E", np.nan)), "E = nan", "data"),
    ("nu = 0.5", lambda good, plain, d: _edit(good, d, "nu.h5", _attr("nu", 0.5)), "nu = 0.5", "data"),
    ("E a string", lambda good, plain, d: _edit(good, d, "es.h5", _attr("E", "stiff")), "not of type float", "data"),
    ("a value changed after writing", lambda good, plain, d: _edit(good, d, "flip.h5", _flip_checksummed),
     "does not match its checksum", "data"),
)


def rust_runs(directory):
    """Good files for the corpus, written by the Rust binary: {"contact": mms_stop (Γ_C, exact errors),
    "plain": elastic_rect (no Γ_C)}, each with its XDMF sidecar; None when the binary is not built."""
    import subprocess

    from .common import BIN, case
    if not os.path.exists(BIN):
        return None
    out = {}
    for key, scene in (("contact", "mms_stop"), ("plain", "elastic_rect")):
        out[key] = os.path.join(directory, f"{key}.h5")
        subprocess.run([BIN, "run", case(scene), "-q", "-o", out[key], "--force"], check=True,
                       capture_output=True)
    return out


def rust_runs_or_skip(tmp_path_factory):
    """``rust_runs`` in a pytest temporary directory; the test is skipped when the binary is not built."""
    import pytest
    out = rust_runs(str(tmp_path_factory.mktemp("rust")))
    if out is None:
        pytest.skip("target/release/tresca-cr is not built (cargo build --release)")
    return out


def unprivileged():
    """A command prefix under which permission bits apply (root ignores them: its file-access capabilities
    are dropped with util-linux ``setpriv``); [] for other users."""
    if os.geteuid() != 0:
        return []
    if shutil.which("setpriv") is None:
        return None
    return ["setpriv", "--bounding-set=-dac_override,-dac_read_search,-fowner"]


def _pair(good, d, name, sidecar):
    """A copy of ``good`` as ``d/name.h5`` with the sidecar made by sidecar(path of the .xdmf)."""
    h5 = _copy(good, d, name + ".h5")
    sidecar(os.path.join(d, name + ".xdmf"))
    return h5


def _text(data):
    def make(p):
        with open(p, "w") as f:
            f.write(data)
    return make


# (name, make(good, d) -> results file whose sidecar is hostile, what the refusal says)
SIDECARS = (
    ("sidecar missing", lambda good, d: _pair(good, d, "s1", lambda p: None), "no such file"),
    ("sidecar empty", lambda good, d: _pair(good, d, "s2", _text("")), "is empty"),
    ("sidecar a directory", lambda good, d: _pair(good, d, "s3", os.makedirs), "is a directory"),
    ("sidecar not XML", lambda good, d: _pair(good, d, "s4", _text("time,u\n")), "not an XDMF (XML) file"),
    ("sidecar other XML", lambda good, d: _pair(good, d, "s5", _text("<html><body/></html>")), "is XML but not XDMF"),
    ("sidecar without data", lambda good, d: _pair(good, d, "s6", _text('<Xdmf Version="3.0"><Domain/></Xdmf>')),
     "references no HDF5 data"),
    ("sidecar of a copied pair", lambda good, d: _pair(
        good, d, "s7", lambda p: shutil.copy(os.path.splitext(good)[0] + ".xdmf", p)), "belongs to another"),
    ("sidecar a FIFO", lambda good, d: _pair(good, d, "s8", os.mkfifo), "not a regular file"),
)

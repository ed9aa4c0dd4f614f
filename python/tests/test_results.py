"""tresca_py.results, the one /tresca layout: a round trip of the schema, a file of the Rust binary read field by
field, killed / stopped / legacy files, and every hostile file of tresca_py.hostile refused with its problem named."""
import os

import h5py
import numpy as np
import pytest

from tresca_py import hostile, results
from tresca_py.results import ResultsError


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return hostile.rust_runs_or_skip(tmp_path_factory)


def arrays(r):
    return {**r.static(), **r.series()}


def assert_same(a, b):
    """Every dataset bit-identical in the declared dtype, every attribute equal."""
    A, B = arrays(a), arrays(b)
    assert sorted(A) == sorted(B)
    for k in A:
        assert A[k].dtype == B[k].dtype == results.SPEC[k][0], k
        assert A[k].tobytes() == B[k].tobytes(), k
    for k, v in a.attrs.items():
        assert np.array_equal(v, b.attrs[k]) if isinstance(v, np.ndarray) else v == b.attrs[k], k


def synthetic(contact=True, errors=True, steps=3):
    """Results of a 2-triangle mesh built here (not read from any file)."""
    rng = np.random.default_rng(7)
    pts = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    tri = np.array([[0, 1, 2], [0, 2, 3]])
    edges = np.array([[1, 2], [0, 2], [0, 1], [2, 3], [0, 3]])
    m = results.Mesh(pts, tri, edges, pts[edges].mean(axis=1))
    R = steps + 1
    c = None
    if contact:
        c = results.Contact(np.array([2]), np.array([[0.0, -1.0]]), np.array([[1.0, 0.0]]), np.array([0.5]),
                            rng.normal(size=(R, 1)), rng.normal(size=(R, 1)),
                            rng.integers(0, 2, (R, 1)).astype(np.uint8), rng.normal(size=(R, 1)),
                            rng.normal(size=(R, 1)))
    st = {k: rng.integers(0, 9, R) if k in ("iterations", "n_stick", "n_slip") else rng.random(R)
          for k in results.STEP_FIELDS}
    err = {k: rng.random(R) for k in results.ERRORS} if errors else None
    return results.Results(mesh=m, times=np.linspace(0, 1, R), u=rng.normal(size=(R, 5, 2)), energy=rng.random(R),
                           steps=st, contact=c, errors=err,
                           attrs={"scene": "title = 'x'", "version": "python-2", "solver": "test", "E": 1.0,
                                  "nu": 0.3})


class TestRoundTrip:
    """The system shall write results (tresca_py.results.write) that read back bit for bit equal."""

    @pytest.mark.parametrize("contact,errors", [(True, True), (False, False), (True, False)])
    def test_synthetic(self, tmp_path, contact, errors):
        r = synthetic(contact, errors)
        results.write(tmp_path / "r.h5", r)
        back = results.read(tmp_path / "r.h5")
        assert_same(r, back)
        assert back.status == "completed" and back.completed == 4 and back.n_steps == 3
        assert (back.contact is None) == (not contact) and (back.errors is None) == (not errors)

    def test_rust_file_rewritten(self, runs, tmp_path):
        for key in ("contact", "plain"):
            r = results.read(runs[key])
            results.write(tmp_path / f"{key}.h5", r)
            back = results.read(tmp_path / f"{key}.h5")
            assert_same(r, back)
            # the checksums written here are the Rust binary's: the same XXH64 over the same rows
            with h5py.File(runs[key]) as a, h5py.File(tmp_path / f"{key}.h5") as b:
                assert np.array_equal(a["tresca/steps/checksum"][()], b["tresca/steps/checksum"][()])

    def test_write_refuses_nan_before_writing(self, tmp_path):
        r = synthetic()
        r.contact.mu[1, 0] = np.nan
        with pytest.raises(ResultsError, match="contact/mu holds 1 NaN"):
            results.write(tmp_path / "r.h5", r)
        assert os.listdir(tmp_path) == []

    def test_write_refuses_bad_paths(self, tmp_path):
        with pytest.raises(ResultsError, match="is a directory"):
            results.write(tmp_path, synthetic())
        with pytest.raises(ResultsError, match="cannot create"):
            results.write("/proc/tresca-test.h5", synthetic())

    def test_write_refuses_wrong_shapes(self, tmp_path):
        r = synthetic()
        r.u = r.u[:, :4]
        with pytest.raises(ResultsError, match=r"tresca/u has shape \(4, 4, 2\)"):
            results.write(tmp_path / "r.h5", r)


class TestRustFile:
    """The system shall read every dataset and attribute the schema declares from a file the Rust binary writes,
    in the declared dtype and shape."""

    def test_every_dataset(self, runs):
        with h5py.File(runs["contact"]) as f:
            g = f["tresca"]
            S = g["times"].shape[0]
            sizes = {"P": len(g["mesh/points"]), "T": len(g["mesh/triangles"]), "E": len(g["mesh/edges"]),
                     "C": len(g["contact/edges"]), "R": S}
            for name, dtype, shape, _ in results.DATASETS:
                if name in results.NORMAL_SERIES:           # written only with normal unknowns (unilateral)
                    continue
                if name in results.FLOATING_SERIES:         # written only for a floating body
                    continue
                assert g[name].dtype == dtype, name
                assert g[name].shape == tuple(sizes[s] if isinstance(s, str) else s for s in shape), name
        r = results.read(runs["contact"])
        for name, a in arrays(r).items():
            assert a.dtype == results.SPEC[name][0]
        assert r.contact is not None and r.errors is not None and r.contact.mu is not None

    def test_every_attribute(self, runs):
        for key in ("contact", "plain"):
            r = results.read(runs[key])
            assert sorted(r.attrs) == sorted(results.ATTRIBUTES), key
            assert r.status == "completed" and r.completed == r.n_steps + 1 == r.rows
            assert r.attrs["n_contact"] == (0 if r.contact is None else len(r.contact.edges))

    def test_without_contact(self, runs):
        r = results.read(runs["plain"])
        assert r.contact is None and r.attrs["n_contact"] == 0
        with pytest.raises(ResultsError, match="no contact part"):
            r.require_contact("a contact plot needs one")

    def test_values(self, runs):
        """σ_τ = −μ/|e| and the contact unknown equal to the slip (docs/results.md's table)."""
        r = results.read(runs["contact"])
        m, c = r.mesh, r.contact
        length = np.linalg.norm(np.diff(m.points[m.edges[c.edges]], axis=1)[:, 0], axis=1)
        assert np.allclose(c.sigma_t, -c.mu / length, rtol=1e-14, atol=0)
        assert np.allclose(c.dof, c.slip, rtol=1e-12, atol=1e-15)
        assert np.allclose(m.midpoints, m.points[m.edges].mean(axis=1), rtol=0, atol=1e-15)


class TestRunStates:
    """The system shall read the committed steps of a killed run, a stopped run and a file of the former Python
    writer, and say which it is."""

    def test_killed(self, runs, tmp_path):
        p = tmp_path / "killed.h5"
        p.write_bytes(open(runs["contact"], "rb").read())
        with h5py.File(p, "r+") as f:
            f["tresca"].attrs["status"] = "running"
            f["tresca/steps"].attrs["completed"] = 2
        r = results.read(p)
        assert r.completed == 2 and r.rows == r.n_steps + 1 and r.note.startswith("killed run: 2 of")

    def test_stopped(self, tmp_path):
        r = synthetic()
        r.attrs.update(status="stopped: the solver did not converge", steps=7)
        results.write(tmp_path / "s.h5", r)
        back = results.read(tmp_path / "s.h5")
        assert back.completed == 4 and back.n_steps == 7 and back.note.startswith("stopped run: 4 of 8")

    def test_legacy_python_file(self, tmp_path):
        p = tmp_path / "legacy.h5"
        results.write(p, synthetic())
        with h5py.File(p, "r+") as f:
            g = f["tresca"]
            for k in ("contact/mu", "contact/dof", "steps/checksum"):
                del g[k]
            del g.attrs["status"]
            del g["steps"].attrs["completed"]
            g.attrs["version"] = "python-1"
        r = results.read(p)
        assert r.completed == 4 and r.status == "completed" and r.contact.mu is None

    def test_legacy_rules_apply_only_to_python_files(self, tmp_path):
        p = tmp_path / "r.h5"
        results.write(p, synthetic())
        with h5py.File(p, "r+") as f:
            del f["tresca/contact/mu"]
        with pytest.raises(ResultsError, match="contact/mu is missing"):
            results.read(p)


@pytest.mark.parametrize("name,make,fragment,level", hostile.RESULTS, ids=[h[0] for h in hostile.RESULTS])
def test_read_refuses(runs, tmp_path, name, make, fragment, level):
    """The system shall refuse a hostile results file with a ResultsError that names the file and the problem."""
    path = make(runs["contact"], runs["plain"], str(tmp_path))
    with pytest.raises(ResultsError) as err:
        results.read(path)
    assert fragment in str(err.value) and os.path.basename(path) in str(err.value)
    assert "\n" not in str(err.value)

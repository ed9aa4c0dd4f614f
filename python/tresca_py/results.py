"""The one ``/tresca`` layout of a results file, for writing and reading (docs/results.md's layout table; written
by ``src/output/tresca.rs`` and by ``write`` here for the serial Python solvers).

``read(path)`` returns a validated ``Results`` of the committed steps, or raises ``ResultsError`` naming the
file and the problem: not a readable regular file, not HDF5, truncated, no ``/tresca`` group, a dataset
missing or of the wrong shape or type, attributes missing or inconsistent (``status``, the ``completed``
steps, ``steps``, ``n_contact``), NaN or Inf in any float series, indices out of range, a triangle side that
is not an edge, time nodes not increasing, a step that does not match its checksum.

Sizes: P points, T triangles, E edges, C contact edges (Γ_C; the ``contact`` group exists only when C > 0),
R rows of every series (N + 1 time nodes; a killed run, status "running", has room for all N + 1 but data
in its first ``completed`` rows only; a finished or stopped run has exactly ``completed`` rows, but a stopped
run whose disk had no room to cut its series keeps all N + 1, as a killed run).
"""
import os
from dataclasses import dataclass, field

import numpy as np

from . import checksum, paths
from . import results_layout as layout
# the layout's names, also read as tresca_py.results.X
from .results_layout import ATTRIBUTES as ATTRIBUTES
from .results_layout import (CONTACT_SERIES, CONTACT_STATIC, DATASETS, ERRORS, F8, FLOATING_SERIES, LEGACY_MISSING,
                             NORMAL_SERIES, REQUIRED, SPEC, STEP_FIELDS, ResultsError)


@dataclass(eq=False)
class Mesh:
    points: np.ndarray
    triangles: np.ndarray
    edges: np.ndarray
    midpoints: np.ndarray

    def triangle_edges(self, where="results"):
        """(T, 3): the edge opposite local vertex i of each triangle."""
        P = len(self.points)
        key = np.sort(self.edges, axis=1) @ np.array([P, 1])
        order = np.argsort(key)
        t = self.triangles
        sides = np.stack([t[:, [1, 2]], t[:, [2, 0]], t[:, [0, 1]]], axis=1)
        want = np.sort(sides, axis=2) @ np.array([P, 1])
        pos = np.clip(np.searchsorted(key, want, sorter=order), 0, max(len(key) - 1, 0))
        found = order[pos] if len(key) else np.zeros_like(want)
        bad = np.argwhere(key[found] != want) if len(key) else np.argwhere(np.ones_like(want, bool))
        if len(bad):
            k, i = bad[0]
            raise ResultsError(f"{where}: tresca/mesh/triangles: side {sides[k, i].tolist()} of triangle {k} is not "
                               "an edge of tresca/mesh/edges")
        return found


@dataclass(eq=False)
class Contact:
    edges: np.ndarray
    normal: np.ndarray
    tangent: np.ndarray
    g: np.ndarray
    slip: np.ndarray
    sigma_t: np.ndarray
    state: np.ndarray
    mu: np.ndarray | None
    dof: np.ndarray | None
    pressure: np.ndarray | None = None
    gap: np.ndarray | None = None
    status: np.ndarray | None = None
    force: np.ndarray | None = None
    normal_dof: np.ndarray | None = None
    coulomb: np.ndarray | None = None


@dataclass(eq=False)
class Results:
    """The committed steps of a run (series: first axis = step) and the ``/tresca`` attributes."""
    mesh: Mesh
    times: np.ndarray
    u: np.ndarray
    energy: np.ndarray
    steps: dict
    contact: Contact | None = None
    errors: dict | None = None
    attrs: dict = field(default_factory=dict)
    path: str | None = None
    rows: int | None = None  # rows in the file (> completed for a killed run)
    audit: dict | None = None  # {name: series} of the energy audit when the step checksums cover it

    @property
    def completed(self):
        return len(self.times)

    @property
    def status(self):
        return self.attrs.get("status", "completed")

    @property
    def n_steps(self):
        """N, the run's number of time steps (N + 1 time nodes when it completes)."""
        return int(self.attrs.get("steps", self.completed - 1))

    @property
    def note(self):
        """'' for a completed run, else what happened to it."""
        if self.status.startswith("running"):
            return f"killed run: {self.completed} of {self.n_steps + 1} steps committed"
        if self.status.startswith("stopped"):
            return f"stopped run: {self.completed} of {self.n_steps + 1} steps ({self.status})"
        return ""

    def require_contact(self, why):
        """The contact part, or ResultsError saying that ``why`` needs one."""
        if self.contact is None:
            raise ResultsError(f"{self.path or 'results'}: the run has no contact part (no Γ_C in the scene); {why}")
        return self.contact

    def series(self):
        """{dataset name: array of the committed steps} of every series present, in checksum order."""
        out = {"times": self.times, "u": self.u, "energy": self.energy}
        out.update({f"steps/{k}": self.steps[k] for k in STEP_FIELDS})
        if self.contact is not None:
            out.update({f"contact/{k}": getattr(self.contact, k) for k in CONTACT_SERIES
                        if getattr(self.contact, k) is not None})
        if self.errors is not None:
            out.update({f"errors/{k}": self.errors[k] for k in ERRORS})
        return out

    def static(self):
        """{dataset name: array} of the mesh and the contact geometry."""
        out = {f"mesh/{k}": getattr(self.mesh, k) for k in ("points", "triangles", "edges", "midpoints")}
        if self.contact is not None:
            out.update({f"contact/{k}": getattr(self.contact, k) for k in CONTACT_STATIC})
            if self.contact.coulomb is not None:
                out["contact/coulomb"] = self.contact.coulomb
        return out

    @property
    def audit_checksummed(self):
        """True if the step checksums cover the energy audit (``tresca_py.checksum.covers_audit``)."""
        return self.audit is not None

    def checksums(self):
        """The checksum of every step (``tresca_py.checksum``), the series in their stored dtypes, the audit's last
        when they cover it."""
        s = self.series()
        audit = [np.asarray(self.audit[k], F8) for k in checksum.AUDIT] if self.audit is not None else []
        return checksum.step_checksums([np.asarray(s[k], SPEC[k][0]) for k in checksum.SERIES if k in s] + audit)


def validate(r, where="results"):
    """ResultsError unless the in-memory results fit the layout and hold valid values."""
    m = r.mesh
    sizes = {"P": len(m.points), "T": len(m.triangles), "E": len(m.edges), "R": len(r.times),
             "C": len(r.contact.edges) if r.contact is not None else 0}
    arrays = {**r.static(), **r.series()}
    for name, a in arrays.items():
        a = np.asarray(a)
        layout.check_array(where, name, a.shape, a.dtype, sizes)
        bad = ~np.isfinite(a) if a.dtype.kind == "f" else None
        if name == "contact/coulomb":
            bad = np.isinf(a) | (a < 0)  # NaN marks a Tresca edge; F̄_e is finite and ≥ 0
        if bad is not None and bad.any():
            n, at = int(bad.sum()), np.unravel_index(int(np.argmax(bad)), a.shape)
            step = f"step {at[0]}" if SPEC[name][1][0] == "R" else f"{tuple(map(int, at))}"
            raise ResultsError(f"{where}: tresca/{name} holds {n} NaN/Inf value{'s' * (n > 1)} (first at {step}): "
                               "not a valid result")
    layout.check_indices(where, m.triangles, sizes["P"], "mesh/triangles")
    layout.check_indices(where, m.edges, sizes["P"], "mesh/edges")
    m.triangle_edges(where)
    if sizes["R"] == 0:
        raise ResultsError(f"{where}: no committed step (tresca-cr never leaves such a file under its name)")
    if np.any(np.diff(r.times) <= 0):
        k = int(np.argmax(np.diff(r.times) <= 0)) + 1
        raise ResultsError(f"{where}: tresca/times is not increasing at step {k} ({r.times[k - 1]!r}, {r.times[k]!r})")
    if r.contact is not None:
        c = r.contact
        if sizes["C"] == 0:
            raise ResultsError(f"{where}: a tresca/contact group without contact edges")
        layout.check_indices(where, c.edges, sizes["E"], "contact/edges")
        if len(np.unique(c.edges)) != len(c.edges):
            raise ResultsError(f"{where}: tresca/contact/edges lists an edge twice")
        if np.any((c.state != 0) & (c.state != 1)):
            raise ResultsError(f"{where}: tresca/contact/state holds values other than 0 (stick) and 1 (slip)")
        if c.status is not None and np.any(~np.isin(c.status, (0, 1, 2))):
            raise ResultsError(f"{where}: tresca/contact/status holds values other than 0 (stick), 1 (slip) and 2 "
                               "(separated)")
    E, nu = r.attrs.get("E", 1.0), r.attrs.get("nu", 0.0)
    if not (np.isfinite(E) and E > 0 and np.isfinite(nu) and -1 < nu < 0.5):  # as src/scene/mod.rs requires
        raise ResultsError(f"{where}: attributes E = {E}, nu = {nu}: not a plane-strain material (E > 0, "
                           "-1 < nu < 0.5)")


def _read_group(f, where, verify):
    import h5py
    g = f.get("tresca")
    if not isinstance(g, h5py.Group):
        top = ", ".join(sorted(f.keys())[:8]) or "nothing"
        raise ResultsError(f"{where}: has no /tresca group (it holds {top}): not a tresca-cr results file")
    attrs = layout.attributes(where, g)
    legacy = "status" not in attrs and str(attrs.get("version", "")).startswith("python")
    for k in REQUIRED:
        if k not in attrs and not (legacy and k in LEGACY_MISSING):
            raise ResultsError(f"{where}: attribute {k} of /tresca is missing")
    ds = {}
    # the Python writer before this module wrote an empty contact group for a run without Γ_C
    has_contact = "contact" in g and not (legacy and layout.dataset(where, g, "contact/edges").shape[:1] == (0,))
    for name in ("mesh/points", "mesh/triangles", "mesh/edges", "times") + (("contact/edges",) if has_contact else ()):
        ds[name] = layout.dataset(where, g, name)
        if ds[name].ndim != len(SPEC[name][1]):
            raise ResultsError(f"{where}: tresca/{name} has {ds[name].ndim} dimensions, the layout wants "
                               f"{len(SPEC[name][1])}")
    sizes = {"P": ds["mesh/points"].shape[0], "T": ds["mesh/triangles"].shape[0], "E": ds["mesh/edges"].shape[0],
             "R": ds["times"].shape[0], "C": ds["contact/edges"].shape[0] if has_contact else 0,
             "K": g["rigid"].shape[-1] if isinstance(g.get("rigid"), h5py.Dataset) else 0}
    if not has_contact and attrs.get("n_contact", 0) > 0:
        raise ResultsError(f"{where}: n_contact = {attrs['n_contact']} but there is no tresca/contact group: "
                           "the contact part of the run is missing")
    if "n_contact" in attrs and attrs["n_contact"] != sizes["C"]:
        raise ResultsError(f"{where}: n_contact = {attrs['n_contact']} but tresca/contact/edges lists {sizes['C']}")
    parts = {"contact": has_contact, "errors": "errors" in g}
    wanted = [n for n, *_ in DATASETS if parts.get(n.split("/")[0], True)]
    for name in wanted:
        optional = (name == "steps/checksum" or name in NORMAL_SERIES or name in FLOATING_SERIES
                    or (legacy and name in LEGACY_MISSING))
        if optional and name not in g:
            continue
        ds[name] = layout.dataset(where, g, name)
        layout.check_array(where, name, ds[name].shape, ds[name].dtype, sizes)
    steps_attrs = g["steps"].attrs if isinstance(g.get("steps"), h5py.Group) else {}
    if "completed" in steps_attrs:
        completed = int(np.asarray(steps_attrs["completed"]).reshape(-1)[0])
    elif legacy:
        completed = sizes["R"]
    else:
        raise ResultsError(f"{where}: attribute completed of tresca/steps is missing")
    status = attrs.get("status", "completed")
    layout.status_rows(where, status, completed, sizes["R"], int(attrs.get("steps", sizes["R"] - 1)))
    S = completed

    def load(name, series=True):
        if name not in ds:
            return None
        a = ds[name][:S] if series else ds[name][()]
        return a.astype(SPEC[name][0], copy=False)

    mesh = Mesh(*(load(f"mesh/{k}", False) for k in ("points", "triangles", "edges", "midpoints")))
    contact = None
    if has_contact:
        contact = Contact(*(load(f"contact/{k}", False) for k in CONTACT_STATIC),
                          *(load(f"contact/{k}") for k in CONTACT_SERIES), load("contact/coulomb", False))
    errors = {k: load(f"errors/{k}") for k in ERRORS} if "errors" in g else None
    r = Results(mesh=mesh, times=load("times"), u=load("u"), energy=load("energy"),
                steps={k: load(f"steps/{k}") for k in STEP_FIELDS}, contact=contact, errors=errors,
                attrs=attrs, path=where, rows=sizes["R"])
    validate(r, where)
    if "steps/checksum" in ds and checksum.covers_audit(ds["steps/checksum"]):
        r.audit = layout.audit_rows(where, g, S, sizes["R"])
    if verify and "steps/checksum" in ds:
        stored = load("steps/checksum")
        bad = np.nonzero(r.checksums() != stored)[0]
        if len(bad):
            raise ResultsError(f"{where}: step {int(bad[0])} does not match its checksum (tresca/steps/checksum): "
                               "the file was damaged after it was written; steps before it are intact")
    return r


def read(path, verify=True):
    """The validated results of the file ``path`` (committed steps only); ResultsError naming the problem.
    ``verify``: check every step against ``tresca/steps/checksum`` when the file has one."""
    import h5py
    try:
        path = paths.hdf5_file(path)
    except paths.PathError as err:
        raise ResultsError(str(err)) from None
    try:
        with h5py.File(path, "r") as f:
            return _read_group(f, path, verify)
    except ResultsError:
        raise
    except (OSError, RuntimeError, KeyError, TypeError, ValueError) as err:
        msg = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise ResultsError(f"{path}: cannot read it as an HDF5 results file: {msg}") from None


def write(path, r, extra_attrs=None):
    """Write ``r`` as a results file at ``path`` (atomically: built beside it, then renamed into place), with
    ``status`` (default "completed"), ``steps`` (default: the committed steps − 1), ``n_edges``,
    ``n_contact``, ``tresca/steps`` attribute ``completed`` and the step checksums. Refuses (ResultsError)
    results that ``read`` would refuse, before anything is written. A serial Python solver writes its run as
    ``write(out, Results(mesh=Mesh(points, triangles, edges, midpoints), times=..., u=..., energy=...,
    steps={"iterations": ..., ...}, contact=Contact(edges, normal, tangent, g, slip, sigma_t, state, mu, dof)
    or None, errors={"energy": ..., "h1": ..., "l2": ...} or None, attrs={"scene": text, "version": ...,
    "solver": ..., "E": ..., "nu": ..., ...}))``."""
    import h5py
    validate(r, "results to write")
    try:
        # the rule of every output (paths.new_output); whether an existing file may be replaced (--force) was
        # decided by the solver's command line before its work
        out = paths.output_file(paths.new_output(path, "results file", force=True), "results file")
    except paths.PathError as err:
        raise ResultsError(str(err)) from None
    attrs = {"status": "completed", "steps": r.completed - 1, **r.attrs, **(extra_attrs or {}),
             "n_edges": len(r.mesh.edges), "n_contact": 0 if r.contact is None else len(r.contact.edges)}
    tmp = f"{out}.{os.getpid()}.partial"
    try:
        with h5py.File(tmp, "w-") as f:
            g = f.create_group("tresca")
            for name, a in {**r.static(), **r.series()}.items():
                g.create_dataset(name, data=np.asarray(a, SPEC[name][0]))
            sums = g.create_dataset("steps/checksum", data=r.checksums())
            if r.audit is not None:
                for k in checksum.AUDIT:
                    g.create_dataset(k, data=np.asarray(r.audit[k], F8))
                sums.attrs[checksum.COVERS] = ", ".join([k for k in checksum.SERIES if k in r.series()]
                                                       + list(checksum.AUDIT))
            for k, v in attrs.items():
                g.attrs[k] = v
            g["steps"].attrs["completed"] = np.int64(r.completed)
        os.replace(tmp, out)
    except BaseException:
        if os.path.lexists(tmp):
            os.unlink(tmp)
        raise

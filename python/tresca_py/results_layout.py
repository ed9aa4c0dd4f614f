"""The ``/tresca`` layout of a results file (docs/results.md's layout table): the datasets, their dtypes and
shapes, the attributes, and the checks of one file's datasets and attributes against it (``tresca_py.results``
reads and writes files of this layout).
"""
import numpy as np

from . import checksum, virtual

F8, I8, U1, U8 = np.dtype("<f8"), np.dtype("<i8"), np.dtype("u1"), np.dtype("<u8")

# (dataset under /tresca, dtype written, shape in the size symbols, meaning)
DATASETS = (
    ("mesh/points", F8, ("P", 2), "vertices"),
    ("mesh/triangles", I8, ("T", 3), "counter-clockwise vertex indices"),
    ("mesh/edges", I8, ("E", 2), "edge vertex indices"),
    ("mesh/midpoints", F8, ("E", 2), "edge midpoints (the CR nodes; tools match edges by these)"),
    ("times", F8, ("R",), "time nodes"),
    ("u", F8, ("R", "E", 2), "displacement at every edge midpoint"),
    ("energy", F8, ("R",), "a_h(u^n, u^n)"),
    ("steps/iterations", I8, ("R",), "solver iterations"),
    ("steps/residual", F8, ("R",), "final residual"),
    ("steps/n_stick", I8, ("R",), "contact edges sticking"),
    ("steps/n_slip", I8, ("R",), "contact edges slipping"),
    ("steps/wall_time", F8, ("R",), "seconds"),
    ("steps/checksum", U8, ("R",), "XXH64 of the step's rows (tresca_py.checksum)"),
    ("contact/edges", I8, ("C",), "indices of the Γ_C edges"),
    ("contact/normal", F8, ("C", 2), "outward normal n_e"),
    ("contact/tangent", F8, ("C", 2), "tangent τ_e = (−n_y, n_x)"),
    ("contact/g", F8, ("C",), "friction bound ḡ_e"),
    ("contact/slip", F8, ("R", "C"), "u_τ(m_e)"),
    ("contact/sigma_t", F8, ("R", "C"), "σ_τ = −μ_e/|e|"),
    ("contact/state", U1, ("R", "C"), "0 stick, 1 slip"),
    ("contact/mu", F8, ("R", "C"), "friction force μ_e, exact"),
    ("contact/dof", F8, ("R", "C"), "the contact unknown"),
    ("contact/pressure", F8, ("R", "C"), "contact pressure p_e = P_e/|e| (scenes with normal unknowns only)"),
    ("contact/gap", F8, ("R", "C"), "u_n(m_e) − ḡ_e (scenes with normal unknowns only)"),
    ("contact/status", U1, ("R", "C"), "0 stick, 1 slip, 2 separated (scenes with normal unknowns only)"),
    ("contact/force", F8, ("R", "C"), "normal force P_e, exact (scenes with normal unknowns only)"),
    ("contact/normal_dof", F8, ("R", "C"), "the normal unknown, exact (scenes with normal unknowns only)"),
    ("contact/coulomb", F8, ("C",), "F̄_e of a Coulomb edge, NaN on a Tresca one (scenes with normal unknowns only)"),
    ("rigid", F8, ("R", "K"), "α, the rigid motions of a floating body, exact; NaN at step 0 (floating bodies only)"),
    ("errors/energy", F8, ("R",), "true energy error"),
    ("errors/h1", F8, ("R",), "true broken H1 error"),
    ("errors/l2", F8, ("R",), "true L2 error"),
)
SPEC = {name: (dtype, shape) for name, dtype, shape, _ in DATASETS}
STEP_FIELDS = ("iterations", "residual", "n_stick", "n_slip", "wall_time")
CONTACT_STATIC = ("edges", "normal", "tangent", "g")
CONTACT_SERIES = ("slip", "sigma_t", "state", "mu", "dof", "pressure", "gap", "status", "force", "normal_dof")
# Written only by a run whose Γ_C edges carry normal unknowns (a unilateral or Coulomb part; issue 40); not part
# of the step checksums (tresca_py.checksum.SERIES), as src/output/tresca.rs writes them.
NORMAL_SERIES = ("contact/pressure", "contact/gap", "contact/status", "contact/force", "contact/normal_dof",
                 "contact/coulomb")
# Written only for a floating body (no Dirichlet part; K its number of rigid motions), for the warm start of
# --resume; not part of the step checksums.
FLOATING_SERIES = ("rigid",)
ERRORS = ("energy", "h1", "l2")

# /tresca attributes as the Rust binary writes them: name -> type ("floats": a 1-D float array)
ATTRIBUTES = {
    "scene": str, "scene_path": str, "title": str, "version": str, "git_commit": str, "solver": str,
    "tol": float, "max_iter": int, "uzawa_step": float, "rho": float, "E": float, "nu": float, "steps": int,
    "n_edges": int, "n_contact": int, "n_dofs": int, "paper_dofs": int, "h": float, "setup_times": "floats",
    "setup_times_meaning": str, "status": str, "frame_every": int, "threads": int,
}
REQUIRED = ("scene", "version", "solver", "E", "nu", "steps", "status")
# Written by the Python solvers before this module: no status, completed, checksum, contact/mu, contact/dof.
LEGACY_MISSING = ("status", "steps/checksum", "contact/mu", "contact/dof")


class ResultsError(ValueError):
    """A results file (or results to be written) that breaks the layout; the message names what."""


def check_array(where, name, shape, dtype, sizes):
    """ResultsError unless a dataset of this shape and dtype fits the layout."""
    sym = SPEC[name][1]
    want = tuple(sizes[s] if isinstance(s, str) else s for s in sym)
    if tuple(shape) != want:
        raise ResultsError(f"{where}: tresca/{name} has shape {tuple(shape)}, the layout wants {want} "
                           f"({', '.join(map(str, sym))})")
    kinds = {"contact/state": "iub", "contact/status": "iub", "steps/checksum": "u"}.get(
        name, "f" if SPEC[name][0].kind == "f" else "iu")
    if np.dtype(dtype).kind not in kinds:
        raise ResultsError(f"{where}: tresca/{name} holds {np.dtype(dtype)}, the layout wants {SPEC[name][0]}")


def check_indices(where, a, n, name):
    if a.size and (a.min() < 0 or a.max() >= n):
        raise ResultsError(f"{where}: tresca/{name} holds indices outside 0..{n - 1} ({int(a.min())}..{int(a.max())})")


def attributes(where, g):
    """The /tresca attributes as Python values, type-checked against ATTRIBUTES."""
    out = {}
    for k, v in g.attrs.items():
        if isinstance(v, bytes):
            v = v.decode("utf-8", "replace")
        elif isinstance(v, np.ndarray) and v.ndim == 0:
            v = v[()]
        if isinstance(v, np.generic):
            v = v.item()
        want = ATTRIBUTES.get(k)
        ok = (want is None or (want is str and isinstance(v, str))
              or (want is int and isinstance(v, int) and not isinstance(v, bool))
              or (want is float and isinstance(v, (int, float)) and not isinstance(v, bool))
              or (want == "floats" and isinstance(v, np.ndarray) and v.ndim == 1 and v.dtype.kind == "f"))
        if not ok:
            raise ResultsError(f"{where}: attribute {k} of /tresca is {v!r}, not of type "
                               f"{getattr(want, '__name__', want)}")
        out[k] = v
    return out


def status_rows(where, status, completed, rows, n_steps):
    """ResultsError unless the status, the completed steps and the rows agree."""
    if not (status == "completed" or status.startswith("running") or status.startswith("stopped")):
        raise ResultsError(f"{where}: unknown status {status!r} (completed, running or stopped: ...)")
    if completed < 1:
        raise ResultsError(f"{where}: no committed step (completed = {completed}); tresca-cr never leaves such "
                           "a file under its name")
    if completed > rows:
        raise ResultsError(f"{where}: {completed} steps marked complete but the series hold {rows} rows: damaged")
    if status == "completed" and not completed == rows == n_steps + 1:
        raise ResultsError(f"{where}: status 'completed' but {completed} committed steps and {rows} rows for "
                           f"{n_steps} steps (N + 1 = {n_steps + 1} expected)")
    if status.startswith("running") and rows != n_steps + 1:
        raise ResultsError(f"{where}: a killed run (status {status!r}) must have room for all {n_steps + 1} "
                           f"steps; the series hold {rows} rows")
    # a stopped run is cut to its completed steps, or left at full length when the disk had no room to cut it
    if status.startswith("stopped") and rows not in (completed, n_steps + 1):
        raise ResultsError(f"{where}: a stopped run must be cut to its {completed} completed steps or left at "
                           f"all {n_steps + 1}; the series hold {rows} rows")


def dataset(where, g, name):
    import h5py
    obj = g.get(name)
    if not isinstance(obj, h5py.Dataset):
        raise ResultsError(f"{where}: tresca/{name} is missing")
    if obj.is_virtual and (missing := virtual.missing_source(obj)):
        raise ResultsError(f"{where}: tresca/{name} is a virtual dataset whose source {missing} is missing; HDF5 "
                           "would read it as zeros, not data")
    return obj


def audit_rows(where, g, S, rows):
    """{name: the first S rows} of the audit series that the checksums cover; ResultsError if one is missing or
    not a float series of the file's rows."""
    import h5py
    out = {}
    for name in checksum.AUDIT:
        obj = g.get(name)
        if not isinstance(obj, h5py.Dataset) or obj.shape != (rows,) or obj.dtype.kind != "f":
            what = "missing" if obj is None else "not a float series of one value per step"
            raise ResultsError(f"{where}: tresca/{name} is {what}, though the step checksums cover the energy audit")
        out[name] = obj[:S].astype(F8, copy=False)
    return out

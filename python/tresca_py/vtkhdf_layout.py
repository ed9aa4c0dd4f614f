"""The sizes a results file's ``/VTKHDF`` view declares, checked against what it holds before VTK's
``vtkHDFReader`` reads it: the reader allocates what is declared and indexes with the stored offsets without
checking them, so a count of 10⁹ in a small file takes gigabytes first, and a ``Steps/Values`` longer than
the other ``Steps`` arrays or an offset past its dataset corrupts its heap (SIGSEGV, or glibc's abort).
``validate`` raises ``ResultsError`` naming the dataset instead.
"""
import os

import numpy as np

from .results import ResultsError

# what each block of /VTKHDF declares, and the dataset that must hold that many rows
DECLARED = (("NumberOfPoints", "Points"), ("NumberOfCells", "Types"), ("NumberOfConnectivityIds", "Connectivity"))
# per time step: the offset into a dataset of the block, and the declared counts that run from there
STEP_OFFSETS = (("PointOffsets", "Points", "NumberOfPoints"), ("CellOffsets", "Types", "NumberOfCells"),
                ("ConnectivityIdOffsets", "Connectivity", "NumberOfConnectivityIds"))
# the offsets of the data arrays: (group under Steps, data group of the block, counts that run from there)
DATA_OFFSETS = (("PointDataOffsets", "PointData", "NumberOfPoints"), ("CellDataOffsets", "CellData", "NumberOfCells"))


def blocks(f):
    """The (name, group) of every block of ``/VTKHDF`` (not its assembly)."""
    import h5py
    root = f.get("VTKHDF")
    return [(k, g) for k, g in root.items() if isinstance(g, h5py.Group) and k != "Assembly"] if root else []


def counts(h5, where, d):
    """The values of dataset (or array) ``d`` as non-negative whole numbers (1-D), else ResultsError naming
    ``where``."""
    n = np.asarray(d).reshape(-1)
    if n.dtype.kind not in "iu" or np.any(n < 0):
        raise ResultsError(f"{h5}: VTKHDF/{where} holds {n.dtype} {n[:4]}, not counts")
    return n.astype(np.int64)


def declared_sizes(h5):
    """ResultsError unless every count a /VTKHDF block declares (points, cells, connectivity ids) is held by its
    dataset and fits the file's size."""
    import h5py
    size = os.path.getsize(h5)
    with h5py.File(h5, "r") as f:
        for name, g in blocks(f):
            for count, held in DECLARED:
                c, d = g.get(count), g.get(held)
                if not (isinstance(c, h5py.Dataset) and isinstance(d, h5py.Dataset)):
                    continue
                need = int(counts(h5, f"{name}/{count}", c).max(initial=0))
                row = d.dtype.itemsize * int(np.prod(d.shape[1:], dtype=np.int64))
                if need > d.shape[0] or need * row > size:
                    raise ResultsError(f"{h5}: VTKHDF/{name}/{count} declares {need}, but VTKHDF/{name}/{held} holds "
                                       f"{d.shape[0]} rows and the file has {size} bytes: damaged, not read")


def step_arrays(h5, name, st):
    """{path under Steps: its first R values} of a block's ``Steps`` group, and R, the values of
    ``Steps/Values``: every array holds at least R ≥ ``NSteps`` (a run that stopped early cuts ``Values`` to
    its frames and keeps room for all of them in the others), else ResultsError."""
    import h5py
    ns = np.asarray(st.attrs.get("NSteps", -1)).reshape(-1)
    if ns.size != 1 or ns.dtype.kind not in "iu" or ns[0] < 0:
        raise ResultsError(f"{h5}: VTKHDF/{name}/Steps has no whole number NSteps ({ns[:4]}): damaged, not read")
    nsteps, out = int(ns[0]), {}
    st.visititems(lambda k, d: out.update({k: d}) if isinstance(d, h5py.Dataset) else None)
    rows = out["Values"].shape[0] if "Values" in out and out["Values"].ndim == 1 else nsteps
    if rows < nsteps:
        raise ResultsError(f"{h5}: VTKHDF/{name}/Steps/Values holds {rows} values, fewer than NSteps = {nsteps}: "
                           "damaged, not read")
    for k, d in out.items():
        if d.ndim != 1 or d.shape[0] < rows:
            raise ResultsError(f"{h5}: VTKHDF/{name}/Steps/{k} has shape {d.shape}, fewer than the {rows} values of "
                               "Steps/Values: damaged, not read")
    return {k: d[:rows] for k, d in out.items()}, rows


def steps(h5):
    """ResultsError unless every block's ``Steps`` arrays hold at least as many values as ``Steps/Values``, it
    at least ``NSteps``, the time values are finite and the offsets of those rows, with the counts their parts
    declare, stay within the block's datasets."""
    import h5py
    with h5py.File(h5, "r") as f:
        for name, g in blocks(f):
            st = g.get("Steps")
            if not isinstance(st, h5py.Group):
                continue
            arrays, nsteps = step_arrays(h5, name, st)  # the rows VTK may read
            if "Values" in arrays and not np.all(np.isfinite(np.asarray(arrays["Values"], dtype=float))):
                raise ResultsError(f"{h5}: VTKHDF/{name}/Steps/Values holds values that are not finite numbers")
            step = {k: counts(h5, f"{name}/Steps/{k}", d) for k, d in arrays.items() if k != "Values"}
            first = step.get("PartOffsets", np.zeros(nsteps, np.int64))
            parts = step.get("NumberOfParts", np.ones(nsteps, np.int64))
            uses = [(f"Steps/{o}", held, n) for o, held, n in STEP_OFFSETS]
            uses += [(f"Steps/{o}/{a}", f"{data}/{a}", n) for o, data, n in DATA_OFFSETS for a in g.get(data, {})]
            for offsets, held, count in uses:
                c, d = g.get(count), g.get(held)
                present = isinstance(c, h5py.Dataset) and isinstance(d, h5py.Dataset)
                if offsets.removeprefix("Steps/") not in step or not present:
                    continue
                declared = np.concatenate([[0], np.cumsum(counts(h5, f"{name}/{count}", c))])
                if np.any(first + parts > len(declared) - 1):
                    raise ResultsError(f"{h5}: VTKHDF/{name}/Steps: a step's parts run past the {len(declared) - 1} "
                                       f"declared in VTKHDF/{name}/{count}: damaged, not read")
                end = step[offsets.removeprefix("Steps/")] + declared[first + parts] - declared[first]
                if np.any(end > d.shape[0]):
                    k = int(np.argmax(end > d.shape[0]))
                    raise ResultsError(f"{h5}: VTKHDF/{name}/{offsets} sends step {k} to rows up to {int(end[k])} of "
                                       f"VTKHDF/{name}/{held}, which holds {d.shape[0]}: damaged, not read")


def validate(h5):
    """``declared_sizes`` and ``steps``: the view can be handed to VTK."""
    declared_sizes(h5)
    steps(h5)

"""The distributed route's parallel VTK output read back with VTK against the results file."""
import glob
import os

import h5py
import numpy as np

from tresca_py.common import short_path as rel


def vtk_check(h5path):
    """The parallel VTK output (OUT_vtk/displacement.pvd -> per-rank .vtu pieces) opened with VTK's
    vtkXMLPUnstructuredGridReader: at the last frame, the mean of the two vertex values of every edge of
    every non-ghost cell (a discontinuous P1 field's value at the edge midpoint) must equal the CR value
    u^N of the results file at that midpoint.  Returns (ok, message)."""
    try:
        import vtk
        from vtk.util.numpy_support import vtk_to_numpy
    except ImportError as e:
        return False, f"vtk not importable: {e}"
    from scipy.spatial import cKDTree
    base = os.path.splitext(h5path)[0] + "_vtk"
    files = sorted(glob.glob(os.path.join(base, "displacement*.pvtu")))
    if not files:
        return False, f"no .pvtu files in {rel(base)}"
    r = vtk.vtkXMLPUnstructuredGridReader()
    r.SetFileName(files[-1])
    r.Update()
    g = r.GetOutput()
    X = vtk_to_numpy(g.GetPoints().GetData())[:, :2]
    U = vtk_to_numpy(g.GetPointData().GetArray("displacement"))[:, :2]
    cells = vtk_to_numpy(g.GetCells().GetConnectivityArray()).reshape(-1, 3)
    gh = g.GetCellData().GetArray("vtkGhostType")
    if gh is not None:
        cells = cells[vtk_to_numpy(gh) == 0]
    a, b = np.concatenate([cells[:, [0, 1]], cells[:, [1, 2]], cells[:, [2, 0]]]).T
    mid, val = 0.5 * (X[a] + X[b]), 0.5 * (U[a] + U[b])
    with h5py.File(h5path, "r") as f:
        M = f["tresca/mesh/midpoints"][()]
        u = f["tresca/u"][-1]
        ntri = f["tresca/mesh/triangles"].shape[0]
    dist, idx = cKDTree(M).query(mid)
    scale = max(float(np.max(np.abs(u))), 1e-300)
    err = float(np.max(np.abs(val - u[idx]))) / scale
    # tolerance: the pieces are ASCII with 16 significant digits, so midpoint means carry ~1e-15 relative
    # rounding; 1e-12 leaves room and still catches any wrong value, ordering or ghost handling
    ok = len(cells) == ntri and float(np.max(dist)) < 1e-9 and err <= 1e-12 and len(np.unique(idx)) == len(M)
    return ok, (
        f"{rel(files[-1])}: {len(cells)} non-ghost cells (results file: {ntri}), "
        f"edge-midpoint means vs u^N: max rel. diff {err:.1e}, every edge seen: {len(np.unique(idx)) == len(M)}"
    )

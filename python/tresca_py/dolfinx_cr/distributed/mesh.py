"""Distributed meshes of a scene: structured slabs generated per rank, Gmsh files read and red-refined on
rank 0, both distributed by ``dolfinx.mesh.create_mesh``; the boundary part of every exterior facet."""
import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import basix.ufl
import dolfinx
import numpy as np
import ufl
from dolfinx import mesh as dmesh

from tresca_py.errors import InputError
from tresca_py.mesh import gmsh_mesh as read_gmsh
from tresca_py.mesh import red_refine

SIDES = ("bottom", "right", "top", "left")


class Fail(Exception):
    """Bad input found on some rank; every rank stops with the message."""


def agree(comm, msg):
    """Collective: if any rank has an error message, every rank raises Fail with the first one."""
    msgs = comm.allgather(msg)
    for m in msgs:
        if m:
            raise Fail(m)


def local_range(rank, n, size):
    q, r = divmod(n, size)
    lo = rank * q + min(rank, r)
    return lo, lo + q + (1 if rank < r else 0)


COORD_EL = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))


def partitioner(comm):
    # interior-facet (jump) integrals across rank boundaries need the cells on both sides
    return dmesh.create_cell_partitioner(dmesh.GhostMode.shared_facet, 2) if comm.size > 1 else None


def structured_mesh(comm, scene):
    """The structured mesh of docs/scene.md, generated in slabs (each rank a contiguous range of points and
    cells in the scene's numbering) and distributed by dolfinx.  Returns (mesh, part tag per local
    exterior facet as a function)."""
    ms = scene.mesh
    names = [b.name for b in scene.boundaries]
    unknown = [n for n in names if n not in SIDES]
    if unknown:
        raise Fail(f"boundary part '{unknown[0]}' does not exist in the mesh (available: {sorted(SIDES)})")
    missing = [s for s in SIDES if s not in names]
    if missing:
        raise Fail(f"the structured mesh side(s) {missing} belong to no [[boundary]] part")
    k = 2 ** ms["refine"]
    n, m = ms["cells"][0] * k, ms["cells"][1] * k
    rank, size = comm.rank, comm.size
    lo, hi = local_range(rank, (n + 1) * (m + 1), size)
    idx = np.arange(lo, hi, dtype=np.int64)
    i, j = idx % (n + 1), idx // (n + 1)
    xi = np.arange(n + 1) / n                 # exactly as tresca_py.mesh.structured_mesh
    eta = np.arange(m + 1) / m
    X = np.stack([xi[i], eta[j]], axis=1)     # reference (unit-square) coordinates
    clo, chi = local_range(rank, n * m, size)
    c = np.arange(clo, chi, dtype=np.int64)
    ci, cj = c % n, c // n
    p00, p10, p11, p01 = cj * (n + 1) + ci, cj * (n + 1) + ci + 1, (cj + 1) * (n + 1) + ci + 1, (cj + 1) * (n + 1) + ci
    if ms["diagonal"] == "first":             # split along p(i,j)-p(i+1,j+1)  (dolfinx DiagonalType.right)
        tri = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:                                     # split along p(i+1,j)-p(i,j+1)  (dolfinx DiagonalType.left)
        tri = np.stack([np.stack([p00, p10, p01], 1), np.stack([p10, p11, p01], 1)], 1)
    msh = dmesh.create_mesh(comm, tri.reshape(-1, 3), ufl.Mesh(COORD_EL), X, partitioner=partitioner(comm))
    del tri, X, idx, i, j, c, ci, cj, p00, p10, p11, p01
    top = msh.topology
    top.create_entities(1)
    top.create_connectivity(1, 2)
    bf = dmesh.exterior_facet_indices(top)
    mid = dmesh.compute_midpoints(msh, 1, bf)[:, :2]     # reference coordinates: sides are exact
    side = np.full(len(bf), -1, dtype=np.int64)
    for s, sel in zip(SIDES, (mid[:, 1] == 0.0, mid[:, 0] == 1.0, mid[:, 1] == 1.0, mid[:, 0] == 0.0), strict=True):
        side[sel] = names.index(s)
    if np.any(side < 0):
        raise Fail("internal: a boundary facet of the structured mesh lies on no side")
    # map the points bilinearly onto the corners (same expression as tresca_py.mesh.structured_mesh)
    cc = np.asarray(ms["corners"], dtype=float)
    x = msh.geometry.x
    Xr, Yr = x[:, 0:1].copy(), x[:, 1:2].copy()
    x[:, :2] = (1 - Xr) * (1 - Yr) * cc[0] + Xr * (1 - Yr) * cc[1] + Xr * Yr * cc[2] + (1 - Xr) * Yr * cc[3]
    return msh, bf, side


def gmsh_mesh(comm, scene):
    """Gmsh file: read (and red-refined) on rank 0, distributed by create_mesh; tags distributed."""
    names = [b.name for b in scene.boundaries]
    err, tri, pts, seg, val = None, np.zeros((0, 3), np.int64), np.zeros((0, 2)), np.zeros((0, 2), np.int64), \
        np.zeros(0, np.int32)
    if comm.rank == 0:
        try:
            mesh = read_gmsh(scene.mesh["file"])
            for _ in range(scene.mesh["refine"]):
                mesh = red_refine(mesh)
            for nm in names:
                if nm not in mesh.boundary_segments:
                    raise InputError(f"boundary part '{nm}' does not exist in the mesh "
                                        f"(available: {sorted(mesh.boundary_segments)})")
            tri, pts = mesh.triangles, mesh.points
            seg = np.concatenate([mesh.boundary_segments[nm] for nm in names]).astype(np.int64)
            val = np.concatenate([np.full(len(mesh.boundary_segments[nm]), ip, np.int32)
                                  for ip, nm in enumerate(names)])
        except InputError as e:
            err = str(e)
    agree(comm, err)
    msh = dmesh.create_mesh(comm, tri, ufl.Mesh(COORD_EL), pts, partitioner=partitioner(comm))
    del tri, pts
    top = msh.topology
    top.create_entities(1)
    top.create_connectivity(1, 2)
    ent, v = dolfinx.io.distribute_entity_data(msh, 1, seg, val)
    tags = dmesh.meshtags_from_entities(msh, 1, dolfinx.graph.adjacencylist(ent.astype(np.int32)),
                                        v.astype(np.int32))
    bf = dmesh.exterior_facet_indices(top)
    side = np.full(top.index_map(1).size_local + top.index_map(1).num_ghosts, -1, np.int64)
    side[tags.indices] = tags.values
    side = side[bf]
    msg = None
    if np.any(side < 0):
        mid = dmesh.compute_midpoints(msh, 1, bf[side < 0][:1])[0, :2]
        msg = (f"boundary edge(s) belong to no [[boundary]] part, e.g. the edge with midpoint {mid.tolist()}")
    agree(comm, msg)
    return msh, bf, side

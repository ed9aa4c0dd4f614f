"""Quasi-static Tresca friction with stabilised CR elements -- distributed DOLFINx 0.11 + PETSc/MUMPS solver.

Usage:  python scripts/dolfinx_distributed.py SCENE.toml -o OUT.h5 [--refine k] [--steps N] [-q]
        mpirun -n 4 python scripts/dolfinx_distributed.py SCENE.toml -o OUT.h5     (same answer)

Same discrete problem as scripts/dolfinx_solve.py and the Rust solver (README, Problem 2 of Porwal &
Wadhawan), but nothing of size O(mesh) is held by one rank:

* Mesh.  Structured scenes: every rank generates a contiguous slab of the scene's points and triangles
  (the scene's numbering and diagonal convention, README "Scenes") and ``dolfinx.mesh.create_mesh``
  partitions and distributes them.  (``dolfinx.mesh.create_rectangle`` would build the whole triangle
  mesh on rank 0 first: C++ ``build_tri`` generates on rank 0 only.)  Sides are tagged on the unit square
  and the points then mapped bilinearly onto the corners.  Gmsh scenes: the file is read on rank 0 with
  meshio (the wheel has no ``gmsh`` module, which ``dolfinx.io.gmsh`` needs; dolfinx's reader also reads
  on rank 0), red-refined there ``refine`` times (dolfinx's own ``refine`` bisects, a different mesh) and
  distributed by ``create_mesh``; facet tags follow with ``dolfinx.io.distribute_entity_data``.
* Space and constraints.  V = vector CR ("CR", 1, (2,)).  a_h and the loads are assembled by dolfinx
  into a distributed PETSc matrix / vector.  The constrained space (zero on Gamma_D midpoints, u.n = 0
  on Gamma_C midpoints) is imposed by a block-diagonal rotation R (identity except [tau n] on contact
  edges): K_r = R^T K R (``PtAP``), then the Dirichlet unknowns and the contact normal unknowns are
  removed by ``zeroRowsColumns`` (unit diagonal, zero right-hand side).  u = R r.
* Factorisation.  K_r is factored once by MUMPS Cholesky through PETSc (``--ksp mumps``, the default),
  or used by CG + GAMG (``--ksp cg-gamg``, rtol 1e-13; for the measured comparison only).
* Contact condensation.  Only the contact unknowns are gathered: C = E^T K_r^{-1} E (n_c x n_c) is the
  contact block of K_r^{-1}, computed by MUMPS as selected entries of the inverse (ICNTL(30), PETSc's
  MatMumpsGetInverseTranspose through ctypes: petsc4py does not wrap it), delivered to rank 0; no dense
  n x n_c block exists.  (``--condense matsolve``: blocked multi-right-hand-side MatMatSolve instead,
  ``--rhs-block`` columns at a time; at 1.57M unknowns on 1 rank, blocks of 32: 76 s and +0.95 GB for C,
  against 10 s and no extra memory for the selected entries.)
  Per step: u_f = K_r^{-1} l^n (distributed), d = E^T u_f - s^{n-1} gathered to rank 0 (n_c numbers),
  the friction problem solved there by the project's exact box-QP step (``tresca_scene.box_qp``),
  mu broadcast, u^n = u_f - K_r^{-1} E mu (distributed).
* True errors are assembled distributed (UFL forms of scripts/dolfinx_solve.py).
* Output, without gathering the field: each rank writes its owned edges (points, triangles, edges,
  midpoints, u at every step) to ``OUT.h5.parts/rank<r>.h5`` with serial h5py; rank 0 writes ``OUT.h5``
  with the contact data, statistics and attributes and HDF5 *virtual datasets* that concatenate the
  parts, so ``OUT.h5`` has the README ``/tresca`` layout (h5py, any HDF5 >= 1.10 reader, and
  scripts/compare.py open it as one file; the parts must stay beside it).  The displacement as
  discontinuous P1 goes to ``OUT_vtk/displacement.pvd`` through dolfinx's parallel VTKFile
  (one .vtu piece per rank and frame + .pvtu/.pvd sidecars; read by ParaView and VTK's
  vtkXMLPUnstructuredGridReader).

Edges are numbered by dolfinx's global CR dof-block numbering (owned ranges in rank order), so the
numbering depends on the number of ranks; tools match edges by midpoint coordinates (scripts/compare.py).
"""
import argparse
import ctypes
import json
import math
import os
import resource
import sys
import time

import numpy as np

from tresca_py import tresca_scene as ts  # noqa: E402

import dolfinx_solver  # noqa: E402,F401  (loads libmpi for the wheel; must precede dolfinx)
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402
import basix.ufl  # noqa: E402
import dolfinx  # noqa: E402
import dolfinx.fem.petsc  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem  # noqa: E402
from dolfinx import mesh as dmesh  # noqa: E402
from dolfinx_solve import error_forms, load_form  # noqa: E402  (sympy -> UFL, loads)

SIDES = ("bottom", "right", "top", "left")


def _abort_on_error(exc_type, exc, tb):
    """An uncaught exception on one rank would leave the others waiting in a collective call forever
    (and MPI_Finalize waiting for them): print it and abort the whole job."""
    sys.__excepthook__(exc_type, exc, tb)
    sys.stderr.flush()
    MPI.COMM_WORLD.Abort(1)


if MPI.COMM_WORLD.size > 1:
    sys.excepthook = _abort_on_error


class Fail(Exception):
    """Bad input found on some rank; every rank stops with the message."""


def agree(comm, msg):
    """Collective: if any rank has an error message, every rank raises Fail with the first one."""
    msgs = comm.allgather(msg)
    for m in msgs:
        if m:
            raise Fail(m)


def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rss_mb():
    """Current resident memory of this process (MB)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


MEMLOG = False


def memlog(comm, what):
    """With --mem-log: every rank's current and peak RSS after a set-up stage (collective)."""
    if MEMLOG:
        v = comm.gather((rss_mb(), peak_mb()), root=0)
        if comm.rank == 0:
            print(f"[mem] {what}: " + ", ".join(f"r{i} {a:.0f}/{b:.0f}" for i, (a, b) in enumerate(v)) + " MB (now/peak)",
                  flush=True)


_LIB = None


def _petsc_lib():
    """The wheel's libpetsc through ctypes, for the two calls petsc4py does not wrap."""
    global _LIB
    if _LIB is None:
        _LIB = ctypes.CDLL(str(dolfinx.fem.petsc.get_petsc_lib()))
        for name in ("MatProductClear", "MatMumpsGetInverseTranspose"):
            f = getattr(_LIB, name)
            f.restype = ctypes.c_int
        _LIB.MatProductClear.argtypes = [ctypes.c_void_p]
        _LIB.MatMumpsGetInverseTranspose.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    return _LIB


def local_range(rank, n, size):
    q, r = divmod(n, size)
    lo = rank * q + min(rank, r)
    return lo, lo + q + (1 if rank < r else 0)


COORD_EL = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))


def partitioner(comm):
    # interior-facet (jump) integrals across rank boundaries need the cells on both sides
    return dmesh.create_cell_partitioner(dmesh.GhostMode.shared_facet, 2) if comm.size > 1 else None


# ----------------------------------------------------------------------------------------------
# mesh (distributed) and boundary parts
# ----------------------------------------------------------------------------------------------
def structured_mesh(comm, scene):
    """The README's structured mesh, generated in slabs (each rank a contiguous range of points and
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
    xi = np.arange(n + 1) / n                 # exactly as tresca_scene.structured_mesh
    eta = np.arange(m + 1) / m
    X = np.stack([xi[i], eta[j]], axis=1)     # reference (unit-square) coordinates
    clo, chi = local_range(rank, n * m, size)
    c = np.arange(clo, chi, dtype=np.int64)
    Ic, J = c % n, c // n
    p00, p10, p11, p01 = J * (n + 1) + Ic, J * (n + 1) + Ic + 1, (J + 1) * (n + 1) + Ic + 1, (J + 1) * (n + 1) + Ic
    if ms["diagonal"] == "first":             # split along p(i,j)-p(i+1,j+1)  (dolfinx DiagonalType.right)
        tri = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:                                     # split along p(i+1,j)-p(i,j+1)  (dolfinx DiagonalType.left)
        tri = np.stack([np.stack([p00, p10, p01], 1), np.stack([p10, p11, p01], 1)], 1)
    msh = dmesh.create_mesh(comm, tri.reshape(-1, 3), ufl.Mesh(COORD_EL), X, partitioner=partitioner(comm))
    del tri, X, idx, i, j, c, Ic, J, p00, p10, p11, p01
    top = msh.topology
    top.create_entities(1)
    top.create_connectivity(1, 2)
    bf = dmesh.exterior_facet_indices(top)
    mid = dmesh.compute_midpoints(msh, 1, bf)[:, :2]     # reference coordinates: sides are exact
    side = np.full(len(bf), -1, dtype=np.int64)
    for s, sel in zip(SIDES, (mid[:, 1] == 0.0, mid[:, 0] == 1.0, mid[:, 1] == 1.0, mid[:, 0] == 0.0), strict=False):
        side[sel] = names.index(s)
    if np.any(side < 0):
        raise Fail("internal: a boundary facet of the structured mesh lies on no side")
    # map the points bilinearly onto the corners (same expression as tresca_scene.structured_mesh)
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
            mesh = ts.gmsh_mesh(scene.mesh["file"])
            for _ in range(scene.mesh["refine"]):
                mesh = ts.red_refine(mesh)
            for nm in names:
                if nm not in mesh.boundary_segments:
                    raise ts.SceneError(f"boundary part '{nm}' does not exist in the mesh "
                                        f"(available: {sorted(mesh.boundary_segments)})")
            tri, pts = mesh.triangles, mesh.points
            seg = np.concatenate([mesh.boundary_segments[nm] for nm in names]).astype(np.int64)
            val = np.concatenate([np.full(len(mesh.boundary_segments[nm]), ip, np.int32)
                                  for ip, nm in enumerate(names)])
        except ts.SceneError as e:
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


# ----------------------------------------------------------------------------------------------
# the distributed problem
# ----------------------------------------------------------------------------------------------
class Problem:
    def __init__(self, scene, comm, args, log):
        self.scene, self.comm, self.args = scene, comm, args
        rank = comm.rank
        self.times_setup = {}
        self.mem_setup = {}
        tic = time.perf_counter()
        self.mem_setup["start"] = peak_mb()        # imports: Python, dolfinx, PETSc, MPI
        memlog(comm, "start")
        msh, bf, side = gmsh_mesh(comm, scene) if "file" in scene.mesh else structured_mesh(comm, scene)
        self.msh = msh
        memlog(comm, "mesh created")
        top = msh.topology
        for d0, d1 in ((2, 1), (1, 0), (2, 0), (0, 2)):
            top.create_connectivity(d0, d1)
        nf_loc = top.index_map(1).size_local + top.index_map(1).num_ghosts
        part_of_facet = np.full(nf_loc, -1, np.int64)
        part_of_facet[bf] = side
        kinds = [b.kind for b in scene.boundaries]

        # CR space; dof block <-> facet (CR dof k of a cell sits at the midpoint of its local facet k)
        self.V = V = fem.functionspace(msh, ("CR", 1, (2,)))
        imap = V.dofmap.index_map
        self.nb_own, nb_loc = imap.size_local, imap.size_local + imap.num_ghosts
        self.b0 = imap.local_range[0]
        self.nb_glob = imap.size_global
        c2f = top.connectivity(2, 1).array.reshape(-1, 3)
        cd = V.dofmap.list
        facet_of_block = np.empty(nb_loc, np.int32)
        facet_of_block[cd.ravel()] = c2f[:cd.shape[0]].ravel()
        f2v = top.connectivity(1, 0).array.reshape(-1, 2)
        nv_loc = top.index_map(0).size_local + top.index_map(0).num_ghosts
        vgeom = dmesh.entities_to_geometry(msh, 0, np.arange(nv_loc, dtype=np.int32))[:, 0]
        vx = msh.geometry.x[vgeom, :2]
        own = facet_of_block[:self.nb_own]
        A, B = vx[f2v[own, 0]], vx[f2v[own, 1]]
        mid = 0.5 * (A + B)
        dofx = V.tabulate_dof_coordinates()[:self.nb_own, :2]
        if self.nb_own and np.max(np.abs(mid - dofx)) > 1e-12 * max(1.0, float(np.max(np.abs(dofx)))):
            raise Fail("internal: CR dof coordinates are not the facet midpoints (dolfinx layout changed?)")
        self.midpoints = mid
        self.edges_vertices = top.index_map(0).local_to_global(f2v[own].ravel().astype(np.int32)).reshape(-1, 2)
        # owned vertices and cells for the output (global vertex numbering of dolfinx)
        self.points = vx[:top.index_map(0).size_local]
        nc_own = top.index_map(2).size_local
        c2v = top.connectivity(2, 0).array.reshape(-1, 3)
        cv = c2v[:nc_own]
        p = vx[cv]
        area2 = (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1]) - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        cv = np.where((area2 < 0)[:, None], cv[:, [0, 2, 1]], cv)
        self.triangles = top.index_map(0).local_to_global(cv.ravel().astype(np.int32)).reshape(-1, 3)
        self.n_vertices = top.index_map(0).size_global
        self.n_cells = top.index_map(2).size_global

        # kinds of the owned blocks
        pb = part_of_facet[own]
        kind = np.array(kinds + ["interior"])[pb]          # part -1 (interior) -> last entry
        self.dir_lb = np.flatnonzero(kind == "dirichlet")
        self.con_lb = np.flatnonzero(kind == "contact")
        n_dir = comm.allreduce(len(self.dir_lb))
        if n_dir == 0 and rank == 0:
            print("warning: no Dirichlet edges; a_h may be singular", file=sys.stderr)

        # contact edges (owned): counter-clockwise orientation (interior on the left), tau, n, gbar
        cf = own[self.con_lb]
        a, b = A[self.con_lb].copy(), B[self.con_lb].copy()
        f2c = top.connectivity(1, 2)
        cell = np.array([f2c.links(f)[0] for f in cf], dtype=np.int64)
        third = np.zeros((len(cf), 2))
        for q, (f, cc) in enumerate(zip(cf, cell, strict=False)):
            vs = [v for v in c2v[cc] if v not in f2v[f]]
            third[q] = vx[vs[0]]
        d = b - a
        left = d[:, 0] * (third[:, 1] - a[:, 1]) - d[:, 1] * (third[:, 0] - a[:, 0])
        flip = left < 0
        a[flip], b[flip] = b[flip].copy(), a[flip].copy()
        dvec = b - a
        self.c_len = np.hypot(dvec[:, 0], dvec[:, 1])
        self.tangent = dvec / self.c_len[:, None]
        self.normal = np.stack([self.tangent[:, 1], -self.tangent[:, 0]], 1)
        self.gbar = np.zeros(len(cf))
        msg = None
        for ip, bnd in enumerate(scene.boundaries):
            if bnd.kind != "contact":
                continue
            sel = pb[self.con_lb] == ip
            q = a[sel, None, :] + ts.GAUSS3_S[None, :, None] * (b[sel] - a[sel])[:, None, :]
            g = bnd.g_a(q[..., 0], q[..., 1], 0.0)
            if np.any(g < 0):
                msg = f"boundary '{bnd.name}': g_a is negative somewhere"
            self.gbar[sel] = g @ ts.GAUSS3_W
        agree(comm, msg)
        self.weight = self.c_len * self.gbar
        # global contact list on rank 0 (owned ranges are contiguous in rank order -> sorted)
        self.c_glob = self.b0 + self.con_lb
        allc = comm.gather((self.c_glob, self.midpoints[self.con_lb], self.normal, self.tangent, self.gbar,
                            self.weight, self.c_len), root=0)
        self.n_c = comm.allreduce(len(self.con_lb))
        if rank == 0:
            self.C_edges, self.C_mid, self.C_normal, self.C_tangent, self.C_g, self.C_w, self.C_len = \
                (np.concatenate([x[k] for x in allc]) for k in range(7))
        self.c_counts = comm.allgather(len(self.con_lb))
        self.c_offset = int(np.sum(self.c_counts[:rank]))

        # initial value: edge means of u0 (3-point Gauss) on the owned edges, in rotated unknowns
        q = A[:, None, :] + ts.GAUSS3_S[None, :, None] * (B - A)[:, None, :]
        u0 = scene.u0(q[..., 0], q[..., 1], scene.times[0]) @ ts.GAUSS3_W        # (2, nb_own)
        r0 = u0.T.copy()
        r0[self.dir_lb] = 0.0
        r0[self.con_lb, 0] = np.sum(r0[self.con_lb] * self.tangent, axis=1)
        r0[self.con_lb, 1] = 0.0
        self.r0 = r0.ravel()
        del q, u0, r0, A, B
        self.times_setup["mesh"] = time.perf_counter() - tic
        self.mem_setup["mesh"] = peak_mb()

        # forms (as scripts/dolfinx_solve.py)
        tic = time.perf_counter()
        tags_idx = np.argsort(bf)
        self.ft = dmesh.meshtags(msh, 1, bf[tags_idx].astype(np.int32), (side[tags_idx] + 1).astype(np.int32))
        ids = {k: tuple(i + 1 for i, bb in enumerate(scene.boundaries) if bb.kind == k)
               for k in ("dirichlet", "neumann", "contact")}
        lam, mu, rho = scene.lam, scene.mu, scene.rho
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
        sigma = lambda w: lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2 * mu * eps(w)  # noqa: E731
        dx0 = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": 0})
        dS2 = ufl.Measure("dS", domain=msh, metadata={"quadrature_degree": 3})   # 2-point Gauss
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.ft)
        h = ufl.FacetArea(msh)
        pen = 2.0 * rho * mu / h
        a_h = ufl.inner(sigma(u), eps(v)) * dx0 + 2.0 * rho * mu / h("+") * ufl.inner(ufl.jump(u), ufl.jump(v)) * dS2
        if ids["dirichlet"]:
            a_h = a_h + pen * ufl.inner(u, v) * ds(ids["dirichlet"], metadata={"quadrature_degree": 3})
        a_form = fem.form(a_h)
        memlog(comm, "a_h compiled")
        K = dolfinx.fem.petsc.assemble_matrix(a_form)
        K.assemble()
        memlog(comm, "K assembled")
        # rotation R: owned rows, identity except [tau n] on contact edges
        nloc = 2 * self.nb_own
        gb = 2 * self.b0
        rows_nnz = np.ones(nloc, np.int32)
        rows_nnz[2 * self.con_lb] = 2
        rows_nnz[2 * self.con_lb + 1] = 2
        indptr = np.concatenate([[0], np.cumsum(rows_nnz)]).astype(PETSc.IntType)
        cols = np.empty(indptr[-1], PETSc.IntType)
        vals = np.ones(indptr[-1])
        plain = np.ones(nloc, bool)
        plain[2 * self.con_lb] = plain[2 * self.con_lb + 1] = False
        cols[indptr[:-1][plain]] = gb + np.flatnonzero(plain)
        for comp in (0, 1):            # row 2e+comp: u_comp = tau_comp * s + n_comp * q
            st = indptr[2 * self.con_lb + comp]
            cols[st] = gb + 2 * self.con_lb
            cols[st + 1] = gb + 2 * self.con_lb + 1
            vals[st] = self.tangent[:, comp]
            vals[st + 1] = self.normal[:, comp]
        N = 2 * self.nb_glob
        self.R = PETSc.Mat().createAIJ(((nloc, N), (nloc, N)), csr=(indptr, cols, vals), comm=comm)
        self.R.assemble()
        Kr = K.PtAP(self.R)
        K.destroy()
        # PtAP keeps its intermediate products for a later re-use (the size of K again in parallel);
        # there is none, so free them (MatProductClear is not wrapped by petsc4py)
        _petsc_lib().MatProductClear(ctypes.c_void_p(Kr.handle))
        del a_form
        memlog(comm, "K_r = R^T K R")
        cons = np.concatenate([2 * self.dir_lb, 2 * self.dir_lb + 1, 2 * self.con_lb + 1]) + gb
        self.cons_local = np.sort(cons - gb)
        Kr.zeroRowsColumns(np.sort(cons).astype(PETSc.IntType), diag=1.0)
        Kr.setOption(PETSc.Mat.Option.SPD, True)
        self.Kr = Kr

        # loads
        self.t = fem.Constant(msh, 0.0)
        self.L = load_form(scene, msh, v, ds, self.t)
        self.lvec = dolfinx.fem.petsc.create_vector(V)     # ghosted, layout of V

        # true errors
        self.uh = fem.Function(V)
        self.err_forms = None
        if scene.exact_u is not None:
            self.err_forms = error_forms(scene, self.uh, self.t, (lam, mu, rho, pen), h, dS2, ds, ids["dirichlet"])
        self.times_setup["assembly"] = time.perf_counter() - tic
        memlog(comm, "loads and error forms compiled")
        self.mem_setup["assembly"] = peak_mb()

        # factorisation / solver
        tic = time.perf_counter()
        # MUMPS' workspace is sized from its analysis estimate + ICNTL(14) %; with parallel dynamic
        # scheduling the estimate can fall short (INFOG(1) = -9, seen intermittently on a tiny mesh at
        # 3 ranks): then factorise again with a larger relaxation, as the MUMPS guide advises
        for relax in (30, 100, 400):
            ksp, info = self._factorise(Kr, args, relax)
            if args.ksp != "mumps" or info[0] not in (-8, -9, -11, -12, -13, -14, -15, -17, -20):
                break
            if comm.rank == 0:
                print(f"note: MUMPS workspace too small (INFOG(1) = {info[0]}) with ICNTL(14) = {relax} %; "
                      "factorising again", file=sys.stderr, flush=True)
            ksp.destroy()
        self.ksp = ksp
        self.mumps = {}
        if args.ksp == "mumps":
            F = ksp.getPC().getFactorMatrix()
            if info[0] < 0:      # PETSc records a failed MUMPS factorisation without raising
                raise RuntimeError(f"MUMPS factorisation failed: INFOG(1) = {info[0]}, INFOG(2) = {info[1]} "
                                   "(see the MUMPS users' guide)")
            e29 = F.getMumpsInfog(29)       # entries in the factor (negative: millions)
            self.mumps = {"factor_entries": float(-e29 * 1e6 if e29 < 0 else e29),
                          "flops": float(F.getMumpsRinfog(3)),
                          "mem_max_rank_mb": int(F.getMumpsInfog(21)), "mem_total_mb": int(F.getMumpsInfog(22)),
                          "ordering": int(F.getMumpsInfog(7)), "icntl14": relax}
        self.times_setup["factorisation"] = time.perf_counter() - tic
        memlog(comm, "factorised")
        self.mem_setup["factorisation"] = peak_mb()
        self.n_solves = 0
        self.ksp_its = []

        # vectors
        self.uf = Kr.createVecRight()
        self.w = Kr.createVecRight()
        self.ur = Kr.createVecRight()
        self.rhs = Kr.createVecRight()
        self.tmp = Kr.createVecRight()

        # condensed operator C = E^T K_r^{-1} E on rank 0
        tic = time.perf_counter()
        self.C = self._condense(log)
        self.times_setup["condensation"] = time.perf_counter() - tic
        memlog(comm, "C built")
        self.mem_setup["condensation"] = peak_mb()

    def _factorise(self, Kr, args, relax):
        """KSP on K_r: MUMPS Cholesky (set up = factorised) or CG + GAMG.  Returns (ksp, MUMPS INFOG(1:2))."""
        comm = self.comm
        ksp = PETSc.KSP().create(comm)
        ksp.setOptionsPrefix("tresca_")
        ksp.setOperators(Kr)
        opts = PETSc.Options()
        info = (0, 0)
        if args.ksp == "mumps":
            ksp.setType("preonly")
            pc = ksp.getPC()
            pc.setType("cholesky")
            pc.setFactorSolverType("mumps")
            pc.setFactorSetUpSolverType()
            F = pc.getFactorMatrix()
            if args.mumps_analysis == "parallel":
                F.setMumpsIcntl(28, 2)      # parallel analysis
                F.setMumpsIcntl(29, 1)      # PT-Scotch (the MUMPS of the wheel has no ParMETIS)
            else:
                F.setMumpsIcntl(28, 1)      # sequential analysis on the host
                F.setMumpsIcntl(7, 5)       # METIS nested dissection
            F.setMumpsIcntl(14, relax)      # workspace relaxation (%)
            ksp.setFromOptions()
            ksp.setUp()
            info = (F.getMumpsInfog(1), F.getMumpsInfog(2))
        else:
            ksp.setType("cg")
            ksp.getPC().setType("gamg")
            ksp.setTolerances(rtol=1e-13, atol=0.0, max_it=10000)
            ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
            # near null space: rigid motions in the rotated unknowns, constrained entries zero
            xy = self.midpoints
            modes = []
            for fx, fy in ((np.ones(len(xy)), np.zeros(len(xy))), (np.zeros(len(xy)), np.ones(len(xy))),
                           (-xy[:, 1], xy[:, 0])):
                vv = np.stack([fx, fy], 1)
                vv[self.con_lb] = np.stack([np.sum(vv[self.con_lb] * self.tangent, 1), np.zeros(len(self.con_lb))], 1)
                vv = vv.ravel()
                vv[self.cons_local] = 0.0
                w = Kr.createVecRight()
                w.array[:] = vv
                modes.append(w)
            Kr.setNearNullSpace(PETSc.NullSpace().create(vectors=modes, comm=comm))
            opts["tresca_pc_gamg_threshold"] = 0.01
            ksp.setFromOptions()
            ksp.setUp()
        return ksp, info

    def solve(self, b, x):
        self.ksp.solve(b, x)
        r = self.ksp.getConvergedReason()
        if r < 0:
            raise RuntimeError(f"linear solve failed: KSP reason {r}")
        self.ksp_its.append(self.ksp.getIterationNumber())
        self.n_solves += 1

    def gather_contact(self, vec):
        """Contact unknowns (tangential components) of a rotated vector, on rank 0 in contact order."""
        loc = vec.getArray(readonly=True)[2 * self.con_lb].copy()
        parts = self.comm.gather(loc, root=0)
        return np.concatenate(parts) if self.comm.rank == 0 else None

    def _condense(self, log):
        comm, nc = self.comm, self.n_c
        self.condense_path = "none (no contact edges)"
        if nc == 0:
            return np.zeros((0, 0)) if comm.rank == 0 else None
        Cm = np.zeros((nc, nc)) if comm.rank == 0 else None
        my = 2 * self.con_lb
        self.condense_path = self.args.condense if self.args.ksp == "mumps" else "ksp"
        if self.args.ksp == "mumps" and self.args.condense == "inverse":
            return self._condense_inverse()
        if self.args.ksp == "mumps":
            nb = max(1, min(nc, self.args.rhs_block))
            F = self.ksp.getPC().getFactorMatrix()
            nloc, N = self.Kr.getLocalSize()[0], self.Kr.getSize()[0]
            for c0 in range(0, nc, nb):
                c1 = min(nc, c0 + nb)
                Bm = PETSc.Mat().createDense(((nloc, N), (None, c1 - c0)), comm=comm)
                Bm.setUp()
                Xm = PETSc.Mat().createDense(((nloc, N), (None, c1 - c0)), comm=comm)
                Xm.setUp()
                arr = Bm.getDenseArray()
                arr[:] = 0.0
                # column k of this block: unit vector at the contact unknown of contact edge c0 + k
                mine = np.arange(self.c_offset, self.c_offset + len(my))
                sel = (mine >= c0) & (mine < c1)
                arr[my[sel], mine[sel] - c0] = 1.0
                Bm.assemble()
                F.matSolve(Bm, Xm)
                self.n_solves += c1 - c0
                rows = Xm.getDenseArray()[my, :].copy()
                Bm.destroy()
                Xm.destroy()
                parts = comm.gather(rows, root=0)
                if comm.rank == 0:
                    Cm[:, c0:c1] = np.concatenate(parts, axis=0)
        else:
            e = self.Kr.createVecRight()
            x = self.Kr.createVecRight()
            for k in range(nc):
                e.set(0.0)
                if self.c_offset <= k < self.c_offset + len(my):
                    e.array[my[k - self.c_offset]] = 1.0
                self.solve(e, x)
                col = self.gather_contact(x)
                if comm.rank == 0:
                    Cm[:, k] = col
        return 0.5 * (Cm + Cm.T) if comm.rank == 0 else None

    def _condense_inverse(self):
        """C = the contact block of K_r^{-1}, computed by MUMPS as selected entries of the inverse
        (ICNTL(30), PETSc's MatMumpsGetInverseTranspose, which petsc4py does not wrap: called through
        ctypes on the wheel's libpetsc).  The requested pattern (n_c x n_c entries) lives on rank 0,
        which receives the entries; no dense n x n_c block is formed."""
        comm, nc = self.comm, self.n_c
        F = self.ksp.getPC().getFactorMatrix()
        N = self.Kr.getSize()[0]
        if comm.rank == 0:
            idx = (2 * self.C_edges).astype(PETSc.IntType)          # sorted
            counts = np.zeros(N, PETSc.IntType)
            counts[idx] = nc
            indptr = np.concatenate([[0], np.cumsum(counts)]).astype(PETSc.IntType)
            cols = np.tile(idx, nc).astype(PETSc.IntType)
            vals = np.ones(nc * nc)
            sizes = ((N, N), (N, N))
        else:
            indptr, cols, vals = np.zeros(1, PETSc.IntType), np.zeros(0, PETSc.IntType), np.zeros(0)
            sizes = ((0, N), (0, N))
        S = PETSc.Mat().createAIJ(sizes, csr=(indptr, cols, vals), comm=comm)
        S.assemble()
        keep = {k: F.getMumpsIcntl(k) for k in (20, 21, 30)}
        ierr = _petsc_lib().MatMumpsGetInverseTranspose(ctypes.c_void_p(F.handle), ctypes.c_void_p(S.handle))
        info = (F.getMumpsInfog(1), F.getMumpsInfog(2), F.getMumpsInfo(1), F.getMumpsInfo(2))
        for k, v in keep.items():                 # back to ordinary solves
            F.setMumpsIcntl(k, v)
        if comm.allreduce(ierr, op=MPI.MAX):
            raise RuntimeError(f"MatMumpsGetInverseTranspose failed (PETSc error {ierr}; MUMPS INFOG(1:2), "
                               f"INFO(1:2) on rank {comm.rank}: {info}; local rows {self.Kr.getLocalSize()[0]}, contact {len(self.con_lb)})")
        self.n_solves += nc
        Cm = None
        if comm.rank == 0:
            ip, jj, vv = S.getValuesCSR()
            Cm = np.empty((nc, nc))
            for k, i in enumerate(idx):
                if not np.array_equal(jj[ip[i]:ip[i + 1]], idx):
                    raise RuntimeError("MatMumpsGetInverseTranspose changed the requested pattern")
                Cm[k] = vv[ip[i]:ip[i + 1]]
            Cm = 0.5 * (Cm + Cm.T)
        S.destroy()
        return Cm

    def load(self, t):
        """l_r = R^T l(t) with the constrained entries zero (into self.rhs)."""
        b = self.lvec
        with b.localForm() as bl:
            bl.set(0.0)
        if self.L is not None:
            self.t.value = t
            dolfinx.fem.petsc.assemble_vector(b, self.L)
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        self.R.multTranspose(b, self.rhs)
        self.rhs.array[self.cons_local] = 0.0
        return self.rhs

    def to_function(self, ur):
        self.R.mult(ur, self.uh.x.petsc_vec)
        self.uh.x.scatter_forward()

    def energy(self, ur):
        self.Kr.mult(ur, self.tmp)
        return ur.dot(self.tmp)

    def errors(self, t):
        self.t.value = t
        loc = np.array([fem.assemble_scalar(f) for f in self.err_forms])
        return self.comm.allreduce(loc, op=MPI.SUM)


# ----------------------------------------------------------------------------------------------
# output: per-rank parts + one file with virtual datasets
# ----------------------------------------------------------------------------------------------
class PartWriter:
    def __init__(self, out, prob, n_times):
        import h5py
        comm = prob.comm
        self.dir = out + ".parts"
        if comm.rank == 0:
            os.makedirs(self.dir, exist_ok=True)
            for f in os.listdir(self.dir):
                if f.startswith("rank") and f.endswith(".h5"):
                    os.remove(os.path.join(self.dir, f))
        comm.barrier()
        self.path = os.path.join(self.dir, f"rank{comm.rank}.h5")
        self.h5 = h5py.File(self.path, "w")
        g = self.h5
        g["points"] = prob.points
        g["triangles"] = prob.triangles
        g["edges"] = prob.edges_vertices
        g["midpoints"] = prob.midpoints
        chunk = (1, max(1, prob.nb_own), 2)
        self.u = g.create_dataset("u", shape=(n_times, prob.nb_own, 2), dtype="f8",
                                  chunks=chunk if prob.nb_own else None)

    def write(self, n, u_owned):
        self.u[n] = u_owned.reshape(-1, 2)

    def close(self):
        self.h5.close()


def write_main(out, prob, res, writer_dirname, sizes, attrs):
    """Rank 0: the README /tresca layout, the big arrays as virtual datasets over the parts."""
    import h5py
    scene = prob.scene
    N1 = len(scene.times)
    P = len(sizes)
    rel = os.path.basename(writer_dirname)
    with h5py.File(out, "w") as h5:
        g = h5.create_group("tresca")

        def vds(name, key, tail, dtype, lead=()):
            total = sum(s[key] for s in sizes)
            lay = h5py.VirtualLayout(shape=lead + (total,) + tail, dtype=dtype)
            o = 0
            for r in range(P):
                nr = sizes[r][key]
                if nr:
                    src = h5py.VirtualSource(f"{rel}/rank{r}.h5", name, shape=lead + (nr,) + tail)
                    if lead:
                        lay[:, o:o + nr] = src
                    else:
                        lay[o:o + nr] = src
                o += nr
            g.create_virtual_dataset(f"mesh/{name}" if name != "u" else "u", lay,
                                     fillvalue=np.nan if dtype == "f8" else -1)

        vds("points", "points", (2,), "f8")
        vds("triangles", "triangles", (3,), "i8")
        vds("edges", "edges", (2,), "i8")
        vds("midpoints", "edges", (2,), "f8")
        vds("u", "edges", (2,), "f8", lead=(N1,))
        g.create_dataset("times", data=scene.times)
        g.create_dataset("energy", data=res["energy"])
        g.create_dataset("contact/edges", data=prob.C_edges)
        g.create_dataset("contact/normal", data=prob.C_normal.reshape(-1, 2))
        g.create_dataset("contact/tangent", data=prob.C_tangent.reshape(-1, 2))
        g.create_dataset("contact/g", data=prob.C_g)
        for k in ("slip", "sigma_t", "mu", "state"):
            g.create_dataset(f"contact/{k}", data=res[k])
        g.create_dataset("contact/dof", data=res["slip"])
        for k in ("iterations", "residual", "n_stick", "n_slip", "wall_time"):
            g.create_dataset(f"steps/{k}", data=res[k])
        if "errors" in res:
            for k, v in res["errors"].items():
                g.create_dataset(f"errors/{k}", data=v)
        a = {"scene": scene.text, "scene_path": os.path.abspath(scene.path), "version": "python-distributed-1",
             "git_commit": ts._git_commit(), "solver": "dolfinx-distributed",
             "method": "primal active set on the condensed dual (exact), rank 0",
             "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
             "refine": int(scene.mesh["refine"]), "steps": N1 - 1, "n_edges": prob.nb_glob,
             "n_contact": prob.n_c, "n_dofs": 2 * prob.nb_glob, "parts": rel}
        a.update(attrs)
        for k, v in a.items():
            g.attrs[k] = v


# ----------------------------------------------------------------------------------------------
def main(argv=None):
    comm = MPI.COMM_WORLD
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="scene TOML file")
    ap.add_argument("-o", "--output", help="results file (default: [output] path of the scene)")
    ap.add_argument("--refine", type=int, default=None, help="override [mesh] refine")
    ap.add_argument("--steps", type=int, default=None, help="override the number of uniform time steps")
    ap.add_argument("-q", "--quiet", action="store_true", help="no per-step log")
    ap.add_argument("--ksp", choices=("mumps", "cg-gamg"), default="mumps",
                    help="linear solver for K_r: MUMPS Cholesky (default) or CG + GAMG (rtol 1e-13)")
    ap.add_argument("--mumps-analysis", choices=("sequential", "parallel"), default="sequential",
                    help="MUMPS analysis: METIS on the host (default) or PT-Scotch in parallel")
    ap.add_argument("--condense", choices=("inverse", "matsolve"), default="inverse",
                    help="MUMPS: C from selected entries of K_r^-1 (ICNTL(30), default) or from blocked MatMatSolve")
    ap.add_argument("--rhs-block", type=int, default=32,
                    help="right-hand sides per MatMatSolve when building C (memory: 2 x n x block doubles)")
    ap.add_argument("--frame-every", type=int, default=None,
                    help="visualisation frame every k steps (default: about 50 frames; 0 = none)")
    ap.add_argument("--mem-log", action="store_true", help="print every rank's RSS after each set-up stage")
    args = ap.parse_args(argv)
    global MEMLOG
    MEMLOG = args.mem_log
    t_start = time.perf_counter()
    log = (lambda *a: print(*a, flush=True)) if comm.rank == 0 and not args.quiet else (lambda *a: None)
    try:
        try:
            scene = ts.load_scene(args.scene, refine=args.refine, steps=args.steps)
        except ts.SceneError as e:
            raise Fail(str(e)) from None
        out = args.output or scene.output
        if not out:
            raise Fail("no output path: give -o OUT.h5 or [output] path in the scene")
        if args.rhs_block < 1:
            raise Fail("--rhs-block must be >= 1")
        if args.frame_every is not None and args.frame_every < 0:
            raise Fail("--frame-every must be >= 0")
        out = os.path.abspath(out)
        try:
            prob = Problem(scene, comm, args, log)
        except ts.SceneError as e:
            raise Fail(str(e)) from None
    except Fail as e:
        if comm.rank == 0:
            print(f"error: {e}", file=sys.stderr, flush=True)
        comm.Barrier()
        sys.exit(2)
    setup_time = time.perf_counter() - t_start
    log(f"set-up {setup_time:.2f} s: " + ", ".join(f"{k} {v:.2f} s" for k, v in prob.times_setup.items())
        + f"; {2 * prob.nb_glob} unknowns, {prob.n_c} contact edges, {comm.size} rank(s)")

    times = scene.times
    N = len(times) - 1
    root = comm.rank == 0
    nc = prob.n_c
    res = None
    if root:
        res = dict(slip=np.zeros((N + 1, nc)), sigma_t=np.zeros((N + 1, nc)), mu=np.zeros((N + 1, nc)),
                   state=np.zeros((N + 1, nc), np.int8), iterations=np.zeros(N + 1, np.int64),
                   residual=np.zeros(N + 1), n_stick=np.zeros(N + 1, np.int64), n_slip=np.zeros(N + 1, np.int64),
                   wall_time=np.zeros(N + 1), energy=np.zeros(N + 1))
        if scene.exact_u is not None:
            res["errors"] = {k: np.zeros(N + 1) for k in ("energy", "h1", "l2")}
    writer = PartWriter(out, prob, N + 1)
    fe = args.frame_every if args.frame_every is not None else max(1, N // 50)
    vis = None
    if fe > 0:
        V1 = fem.functionspace(prob.msh, ("DG", 1, (2,)))
        udg = fem.Function(V1, name="displacement")
        vis = dolfinx.io.VTKFile(comm, os.path.splitext(out)[0] + "_vtk/displacement.pvd", "w")

    ur, uf, w = prob.ur, prob.uf, prob.w
    ur.array[:] = prob.r0
    s_prev = prob.gather_contact(ur)
    mu_prev = np.zeros(nc) if root else None
    step_times = []
    for n, t in enumerate(times):
        tic = time.perf_counter()
        if n > 0:
            prob.solve(prob.load(t), uf)
            sf = prob.gather_contact(uf)
            mu = None
            if root and nc:
                d = sf - s_prev
                mu, its = ts.box_qp(prob.C, d, prob.C_w, mu_prev)
                ds = d - prob.C @ mu
                res["iterations"][n] = its
                res["residual"][n] = ts.kkt_residual(prob.C, d, prob.C_w, mu)
                res["state"][n] = ts.classify(mu, ds, d, prob.C_w)
                res["sigma_t"][n] = -mu / prob.C_len
                res["mu"][n] = mu
                mu_prev = mu.copy()
                s_prev = sf - prob.C @ mu
            if nc:
                mu = comm.bcast(mu, root=0)
                prob.rhs.set(0.0)
                prob.rhs.array[2 * prob.con_lb] = mu[prob.c_offset:prob.c_offset + len(prob.con_lb)]
                prob.solve(prob.rhs, w)
                uf.copy(ur)
                ur.axpy(-1.0, w)
            else:
                uf.copy(ur)
        if root:
            res["slip"][n] = s_prev
            res["n_slip"][n] = int(res["state"][n].sum())
            res["n_stick"][n] = nc - res["n_slip"][n]
        en = prob.energy(ur)
        prob.to_function(ur)
        writer.write(n, prob.uh.x.array[:2 * prob.nb_own])
        if prob.err_forms is not None:
            e = prob.errors(t)
            if root:
                for key, val in zip(("energy", "h1", "l2"), e, strict=False):
                    res["errors"][key][n] = math.sqrt(max(float(val), 0.0))
        if vis is not None and (n % fe == 0 or n == N):
            udg.interpolate(prob.uh)
            vis.write_function(udg, float(t))
        el = time.perf_counter() - tic
        step_times.append(el)
        if root:
            res["energy"][n] = en
            res["wall_time"][n] = el
            if n == N or (N >= 10 and n % max(1, N // 10) == 0):
                extra = f" err_E={res['errors']['energy'][n]:.4e}" if "errors" in res else ""
                log(f"step {n:5d}/{N} t={t:.6g} iters={res['iterations'][n]} slip={res['n_slip'][n]}/{nc} "
                    f"a_h(u,u)={en:.6e}{extra} ({el:.3f} s)")
    if vis is not None:
        vis.close()
    writer.close()
    sizes = comm.gather(dict(points=len(prob.points), triangles=len(prob.triangles), edges=prob.nb_own), root=0)
    total = time.perf_counter() - t_start
    peaks = comm.gather(peak_mb(), root=0)
    mem_setup = comm.gather(prob.mem_setup, root=0)
    comm.barrier()                     # every part is closed before the virtual datasets point at them
    if root:
        attrs = {"total_time": total, "setup_time": setup_time, "mpi_size": comm.size,
                 "setup_times": json.dumps(prob.times_setup),
                 "step_time_median": float(np.median(step_times[1:])) if N else 0.0,
                 "peak_rss_mb": np.array(peaks), "setup_peak_rss_mb": json.dumps(mem_setup),
                 "mumps": json.dumps(prob.mumps), "linear_solver": args.ksp, "condensation": prob.condense_path, "linear_solves": prob.n_solves,
                 "ksp_iterations_max": int(max(prob.ksp_its)) if prob.ksp_its else 0}
        write_main(out, prob, res, writer.dir, sizes, attrs)
        log(f"dolfinx distributed ({comm.size} rank{'s' if comm.size > 1 else ''}): {2 * prob.nb_glob} unknowns, "
            f"{nc} contact edges, {N} steps; set-up {setup_time:.2f} s, total {total:.2f} s, "
            f"peak RSS per rank {', '.join(f'{p:.0f}' for p in peaks)} MB -> {out}")
    comm.barrier()


if __name__ == "__main__":
    main()

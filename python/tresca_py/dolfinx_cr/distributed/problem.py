"""The distributed problem: the CR space on the distributed mesh, the owned edges' kinds and contact data, the
constrained stiffness K_r = R^T K R, the load and error forms, the factorisation and the condensed contact
operator (module docstring of ``tresca_py.dolfinx_cr.distributed``)."""
import ctypes
import os
import resource
import sys
import time

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import dolfinx
import dolfinx.fem.petsc
import numpy as np
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI
from petsc4py import PETSc

from tresca_py.dolfinx_cr.distributed import consistency
from tresca_py.dolfinx_cr.distributed.data import Lifting, boundary_data
from tresca_py.dolfinx_cr.distributed.linear import condense, factorise_relaxed, petsc_lib
from tresca_py.dolfinx_cr.distributed.mesh import Fail, agree, gmsh_mesh, structured_mesh
from tresca_py.dolfinx_cr.forms import error_forms, load_form, stiffness_forms
from tresca_py.errors import InputError
from tresca_py.quadrature import GAUSS3_S, GAUSS3_W
from tresca_py.scene import check_loads


def peak_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def rss_mb():
    """Current resident memory of this process (MB)."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2 ** 20


class MemLog:
    """With --mem-log: every rank's current and peak RSS after a set-up stage (collective)."""

    def __init__(self, comm, enabled):
        self.comm, self.enabled = comm, enabled

    def __call__(self, what):
        if self.enabled:
            v = self.comm.gather((rss_mb(), peak_mb()), root=0)
            if self.comm.rank == 0:
                print(f"[mem] {what}: " + ", ".join(f"r{i} {a:.0f}/{b:.0f}" for i, (a, b) in enumerate(v))
                      + " MB (now/peak)", flush=True)


class Problem:
    """Set up in stages (timed in ``times_setup``, peak memory in ``mem_setup``): mesh and space, edge
    kinds and contact data, initial value, forms and K_r, loads and errors, factorisation, condensation."""

    def __init__(self, scene, comm, args, log, mem_log=False):
        self.scene, self.comm, self.args = scene, comm, args
        self.memlog = memlog = MemLog(comm, mem_log)
        self.times_setup = {}
        self.mem_setup = {}
        tic = time.perf_counter()
        self.mem_setup["start"] = peak_mb()        # imports: Python, dolfinx, PETSc, MPI
        memlog("start")
        msh, bf, side = gmsh_mesh(comm, scene) if "file" in scene.mesh else structured_mesh(comm, scene)
        self.msh = msh
        memlog("mesh created")
        top = msh.topology
        for d0, d1 in ((2, 1), (1, 0), (2, 0), (0, 2)):
            top.create_connectivity(d0, d1)
        nf_loc = top.index_map(1).size_local + top.index_map(1).num_ghosts
        part_of_facet = np.full(nf_loc, -1, np.int64)
        part_of_facet[bf] = side
        self.part_of_facet = part_of_facet
        own, A, B, vx, f2v, c2v = self._space(msh, top)
        pb = part_of_facet[own]
        self._kinds(pb)
        self._contact(own, A, B, vx, f2v, c2v, pb)
        data = boundary_data(scene)
        self.lift = Lifting(self, data, A, B, pb) if data is not None else None
        if self.lift is not None:
            consistency.check(self, A, B, pb)
        self._initial_value(A, B)
        del A, B
        self.times_setup["mesh"] = time.perf_counter() - tic
        self.mem_setup["mesh"] = peak_mb()

        tic = time.perf_counter()
        fm = self._stiffness(bf, side)
        self._loads_and_errors(fm)
        self.times_setup["assembly"] = time.perf_counter() - tic
        memlog("loads and error forms compiled")
        self.mem_setup["assembly"] = peak_mb()

        tic = time.perf_counter()
        self.ksp, self.mumps = factorise_relaxed(self, self.Kr, args)
        self.times_setup["factorisation"] = time.perf_counter() - tic
        memlog("factorised")
        self.mem_setup["factorisation"] = peak_mb()
        self.n_solves = 0
        self.ksp_its = []
        self.uf, self.w, self.ur, self.rhs, self.tmp = (self.Kr.createVecRight() for _ in range(5))

        # condensed operator C = E^T K_r^{-1} E on rank 0
        tic = time.perf_counter()
        self.C = condense(self, log)
        self.times_setup["condensation"] = time.perf_counter() - tic
        memlog("C built")
        self.mem_setup["condensation"] = peak_mb()

    def _space(self, msh, top):
        """The CR space, the owned dof blocks' facets, midpoints and the owned vertices and cells for the
        output. Returns (owned facets, their end points A and B, vertex coordinates, facet->vertex and
        cell->vertex connectivity arrays)."""
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
        area2 = ((p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
                 - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0]))
        cv = np.where((area2 < 0)[:, None], cv[:, [0, 2, 1]], cv)
        self.triangles = top.index_map(0).local_to_global(cv.ravel().astype(np.int32)).reshape(-1, 3)
        self.n_vertices = top.index_map(0).size_global
        self.n_cells = top.index_map(2).size_global

        return own, A, B, vx, f2v, c2v

    def _kinds(self, pb):
        """The owned dof blocks on Dirichlet and contact parts (pb: boundary part of each owned block)."""
        kinds = [b.kind for b in self.scene.boundaries]
        kind = np.array(kinds + ["interior"])[pb]          # part -1 (interior) -> last entry
        self.dir_lb = np.flatnonzero(kind == "dirichlet")
        self.con_lb = np.flatnonzero(kind == "contact")
        n_dir = self.comm.allreduce(len(self.dir_lb))
        if n_dir == 0 and self.comm.rank == 0:
            print("warning: no Dirichlet edges; a_h may be singular", file=sys.stderr)


    def _contact(self, own, A, B, vx, f2v, c2v, pb):
        """Owned contact edges: counter-clockwise orientation (interior on the left), tau, n, gbar, weights;
        the global contact list on rank 0."""
        comm, rank, scene, top = self.comm, self.comm.rank, self.scene, self.msh.topology
        cf = own[self.con_lb]
        a, b = A[self.con_lb].copy(), B[self.con_lb].copy()
        f2c = top.connectivity(1, 2)
        cell = np.array([f2c.links(f)[0] for f in cf], dtype=np.int64)
        third = np.zeros((len(cf), 2))
        for q, (f, cc) in enumerate(zip(cf, cell, strict=True)):
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
            q = a[sel, None, :] + GAUSS3_S[None, :, None] * (b[sel] - a[sel])[:, None, :]
            g = bnd.g_a(q[..., 0], q[..., 1], 0.0)
            if np.any(g < 0):
                msg = f"boundary '{bnd.name}': g_a is negative somewhere"
            self.gbar[sel] = g @ GAUSS3_W
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

    def _initial_value(self, A, B):
        """Edge means of u0 (3-point Gauss) on the owned edges, in rotated unknowns."""
        scene = self.scene
        q = A[:, None, :] + GAUSS3_S[None, :, None] * (B - A)[:, None, :]
        u0 = scene.u0(q[..., 0], q[..., 1], scene.times[0]) @ GAUSS3_W        # (2, nb_own)
        r0 = u0.T.copy()
        r0[self.dir_lb] = 0.0
        r0[self.con_lb, 0] = np.sum(r0[self.con_lb] * self.tangent, axis=1)
        r0[self.con_lb, 1] = 0.0
        self.r0 = r0.ravel()
        del q, u0, r0, A, B

    def _stiffness(self, bf, side):
        """K_r = R^T K R with the constrained rows and columns zeroed (unit diagonal): self.Kr. Returns the
        forms, measures and data the load and error forms share (tresca_py.dolfinx_cr.forms.stiffness_forms)."""
        scene, msh, V, memlog = self.scene, self.msh, self.V, self.memlog
        tags_idx = np.argsort(bf)
        self.ft = dmesh.meshtags(msh, 1, bf[tags_idx].astype(np.int32), (side[tags_idx] + 1).astype(np.int32))
        fm = stiffness_forms(scene, msh, V, self.ft)
        a_int = fm.a_el + fm.a_jump
        a_h = a_int if fm.a_dir is None else a_int + fm.a_dir
        self.a_int, self.a_ufl = a_int, a_h
        a_form = fem.form(a_h)
        memlog("a_h compiled")
        K = dolfinx.fem.petsc.assemble_matrix(a_form)
        K.assemble()
        memlog("K assembled")
        self.R = self._rotation()
        Kr = K.PtAP(self.R)
        K.destroy()
        # PtAP keeps its intermediate products for a later re-use (the size of K again in parallel);
        # there is none, so free them (MatProductClear is not wrapped by petsc4py)
        petsc_lib().MatProductClear(ctypes.c_void_p(Kr.handle))
        del a_form
        memlog("K_r = R^T K R")
        gb = 2 * self.b0
        cons = np.concatenate([2 * self.dir_lb, 2 * self.dir_lb + 1, 2 * self.con_lb + 1]) + gb
        self.cons_local = np.sort(cons - gb)
        Kr.zeroRowsColumns(np.sort(cons).astype(PETSc.IntType), diag=1.0)
        Kr.setOption(PETSc.Mat.Option.SPD, True)
        self.Kr = Kr
        self.v = fm.v
        return fm

    def _rotation(self):
        """R: owned rows, identity except [tau n] on contact edges (u = R r)."""
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
        R = PETSc.Mat().createAIJ(((nloc, N), (nloc, N)), csr=(indptr, cols, vals), comm=self.comm)
        R.assemble()
        return R

    def _loads_and_errors(self, fm):
        scene, msh, V, ds = self.scene, self.msh, self.V, fm.ds
        self.t = fem.Constant(msh, 0.0)
        self.L = load_form(scene, msh, self.v, ds, self.t)
        self.lvec = dolfinx.fem.petsc.create_vector(V)     # ghosted, layout of V
        self.uh = fem.Function(V)
        self.err_forms = None
        if self.lift is not None:
            self.lift.compile(self.a_int, self.a_ufl, fm.pen, ds)
        if scene.exact_u is not None:
            # with boundary data the error's jump on Γ_D is u_h − u: the lifting's form, not u_h alone
            dirichlet = fm.ids["dirichlet"] if self.lift is None else ()
            self.err_forms = error_forms(scene, self.uh, self.t, fm.params, fm.h, fm.dS2, ds, dirichlet)

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

    def load(self, t):
        """l_r = R^T l(t) with the constrained entries zero (into self.rhs)."""
        b = self.lvec
        with b.localForm() as bl:
            bl.set(0.0)
        if self.lift is not None:
            self.lift.set(t)                               # u_L(t) and the time of the forms
            dolfinx.fem.petsc.assemble_vector(b, self.lift.rhs_form)
        if self.L is not None:
            self.t.value = t
            dolfinx.fem.petsc.assemble_vector(b, self.L)
        if self.L is not None or self.lift is not None:
            b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
        if not np.isfinite(b.norm()):                      # collective
            self._name_nonfinite_load(t)
        self.R.multTranspose(b, self.rhs)
        self.rhs.array[self.cons_local] = 0.0
        return self.rhs

    def _name_nonfinite_load(self, t):
        """Collective: Fail naming the load expression that is not finite at a quadrature point of some rank's
        cells or Neumann facets (``tresca_py.scene.check_loads``)."""
        msh, scene = self.msh, self.scene
        x = msh.geometry.x[:, :2]
        neumann = {}
        for ip, b in enumerate(scene.boundaries):
            facets = np.flatnonzero(self.part_of_facet == ip).astype(np.int32)
            if b.kind == "neumann" and len(facets):
                neumann[b.name] = x[dmesh.entities_to_geometry(msh, 1, facets)]
        msg = None
        try:
            check_loads(scene, t, x[msh.geometry.dofmap], neumann)
        except InputError as err:
            msg = str(err)
        agree(self.comm, msg)
        raise Fail(f"the load vector at t = {t:.6g} is not finite (NaN or Inf)")

    def to_function(self, ur, t):
        """u_h = R ur (+ u_L(t) with boundary data): the real displacement."""
        self.R.mult(ur, self.uh.x.petsc_vec)
        self.uh.x.scatter_forward()
        if self.lift is not None:
            self.lift.set(t)
            self.uh.x.array[:] += self.lift.uL.x.array

    def energy(self, ur):
        """a_h(u, u) (with boundary data: of u_h, the Dirichlet jump against u_D; after ``to_function``)."""
        if self.lift is not None:
            return self.lift.energy()
        self.Kr.mult(ur, self.tmp)
        return ur.dot(self.tmp)

    def errors(self, t):
        self.t.value = t
        loc = np.array([fem.assemble_scalar(f) for f in self.err_forms])
        if self.lift is not None and self.lift.err_form is not None:
            loc[0] += fem.assemble_scalar(self.lift.err_form)
        return self.comm.allreduce(loc, op=MPI.SUM)

"""Distributed assembly of a_h, its jump part, loads, the boundary data's forms and true errors with DOLFINx,
gathered to rank 0 in the edge ordering of ``tresca_py.dolfinx_cr.edges.CrEdges`` (edges matched by midpoints)."""
import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import basix.ufl
import numpy as np
import scipy.sparse as sp
import ufl
from dolfinx import fem
from dolfinx import mesh as dmesh
from mpi4py import MPI

from tresca_py.dolfinx_cr.edges import CrEdges
from tresca_py.dolfinx_cr.forms import data_forms, error_forms, load_form, stiffness_forms
from tresca_py.errors import InputError
from tresca_py.mesh import match_points
from tresca_py.scene import check_loads


class DolfinxProblem:
    """Distributed assembly of a_h, its jump part, loads and true errors (canonical ordering on rank 0)."""

    def __init__(self, disc: CrEdges, comm):
        self.disc, self.comm = disc, comm
        scene = disc.scene
        rank = comm.rank
        coord = basix.ufl.element("Lagrange", "triangle", 1, shape=(2,))
        cells = disc.triangles if rank == 0 else np.zeros((0, 3), dtype=np.int64)
        pts = disc.points if rank == 0 else np.zeros((0, 2))
        part = dmesh.create_cell_partitioner(dmesh.GhostMode.shared_facet, 2) if comm.size > 1 else None
        self.msh = msh = dmesh.create_mesh(comm, cells, ufl.Mesh(coord), pts, partitioner=part)
        tdim = 2
        msh.topology.create_connectivity(tdim - 1, tdim)
        self.V = V = fem.functionspace(msh, ("CR", 1, (2,)))
        # canonical index of every local (owned + ghost) scalar dof
        imap = V.dofmap.index_map
        nloc = imap.size_local + imap.num_ghosts
        xy = V.tabulate_dof_coordinates()[:nloc, :2]
        edge = match_points(disc.midpoints, xy, what="dolfinx CR dof coordinates")
        self.canon = np.empty(2 * nloc, dtype=np.int64)
        self.canon[0::2], self.canon[1::2] = 2 * edge, 2 * edge + 1
        # global dof block -> canonical edge, known on every rank
        lo = imap.local_range[0]
        owned = comm.allgather((np.arange(lo, lo + imap.size_local), edge[:imap.size_local]))
        self.edge_of_global = np.empty(imap.size_global, dtype=np.int64)
        for g, e in owned:
            self.edge_of_global[g] = e

        # boundary facet tags: part index + 1 (matched by midpoint to the canonical boundary edges)
        bfacets = dmesh.exterior_facet_indices(msh.topology)
        bmid = dmesh.compute_midpoints(msh, tdim - 1, bfacets)[:, :2]
        bedges = np.flatnonzero(disc.is_boundary)
        k = match_points(disc.midpoints[bedges], bmid, what="dolfinx boundary facets")
        tags = disc.part_of_edge[bedges[k]] + 1
        order = np.argsort(bfacets)
        self.ft = dmesh.meshtags(msh, tdim - 1, bfacets[order], tags[order].astype(np.int32))
        fm = stiffness_forms(scene, msh, V, self.ft)
        v, ds, pen, ids = fm.v, fm.ds, fm.pen, fm.ids
        a_j = fm.a_jump if fm.a_dir is None else fm.a_jump + fm.a_dir
        self.J = self._gather_matrix(fem.form(a_j))
        Kel = self._gather_matrix(fem.form(fm.a_el))
        self.K = None if rank else (Kel + self.J).tocsr()

        # loads: UFL expressions in x and the time constant t
        self.t = fem.Constant(msh, 0.0)
        self.L = load_form(scene, msh, v, ds, self.t)

        # boundary data: b_D(t; v) and c(t) on the Dirichlet parts with `u` (tresca_py.dolfinx_cr.stepping)
        with_u = tuple(i + 1 for i, b in enumerate(scene.boundaries) if b.kind == "dirichlet" and b.u is not None)
        self.b_d, self.c_d = data_forms(scene, msh, v, ds, self.t, pen, with_u) if with_u else (None, None)

        # true errors
        self.err_forms = None
        if scene.exact_u is not None:
            self.uh = fem.Function(V)
            self.err_forms = error_forms(scene, self.uh, self.t, fm.params, fm.h, fm.dS2, ds, ids["dirichlet"],
                                         data=scene.has_boundary_data)

    def _gather_matrix(self, form):
        A = fem.assemble_matrix(form)             # not finalised: ghost rows hold partial sums
        S = A.to_scipy(ghosted=True).tocoo()      # local (owned + ghost) rows, local columns
        b0, b1 = A.block_size
        # the matrix has its own row/column index maps (the column map carries extra ghosts):
        # local block -> global block -> canonical edge
        rows = A.index_map(0).local_to_global((S.row // b0).astype(np.int32))
        cols = A.index_map(1).local_to_global((S.col // b1).astype(np.int32))
        trip = (2 * self.edge_of_global[rows] + S.row % b0, 2 * self.edge_of_global[cols] + S.col % b1, S.data)
        allt = self.comm.gather(trip, root=0)
        if self.comm.rank:
            return None
        n = self.disc.n_dofs
        r, c, d = (np.concatenate([a[i] for a in allt]) for i in range(3))
        return sp.csr_matrix((d, (r, c)), shape=(n, n))

    def load(self, t):
        """(l(t), ·) on rank 0 (collective)."""
        return self._gather_vector(self.L, t)

    def data_vector(self, t):
        """b_D(t; ·) on rank 0 (collective; zero without Dirichlet data)."""
        return self._gather_vector(self.b_d, t)

    def data_norm(self, t):
        """c(t) = Σ_{Γ_D} (2ρμ/h_e) ∫_e |u_D(t)|² (collective)."""
        if self.c_d is None:
            return 0.0
        self.t.value = t
        return float(self.comm.allreduce(fem.assemble_scalar(self.c_d), op=MPI.SUM))

    def _gather_vector(self, form, t):
        self.t.value = t
        if form is None:
            vals = np.zeros(0)
            idx = np.zeros(0, dtype=np.int64)
        else:
            b = fem.assemble_vector(form)         # owned + ghost entries, ghosts not accumulated
            vals, idx = b.array.copy(), self.canon
        if self.comm.allreduce(not np.all(np.isfinite(vals)), op=MPI.LOR):
            self._name_nonfinite_load(t)
        allv = self.comm.gather((idx, vals), root=0)
        if self.comm.rank:
            return None
        out = np.zeros(self.disc.n_dofs)
        for i, v in allv:
            np.add.at(out, i, v)
        return out

    def _name_nonfinite_load(self, t):
        """Raise InputError naming the load expression that is not finite at a quadrature point (every rank
        holds the whole Discretisation, so every rank raises the same error)."""
        disc = self.disc
        p = disc.points
        check_loads(disc.scene, t, p[disc.triangles], {name: p[disc.edges[e]] for name, e in disc.neumann.items()})
        disc.lifting(t)                       # names a `u` data expression that is not finite
        raise InputError(f"the load vector at t = {t:.6g} is not finite (NaN or Inf)")

    def errors(self, t, u_canon):
        self.t.value = t
        self.uh.x.array[:] = u_canon[self.canon]
        loc = np.array([fem.assemble_scalar(f) for f in self.err_forms])
        tot = self.comm.allreduce(loc, op=MPI.SUM)
        return tuple(float(v) for v in tot)

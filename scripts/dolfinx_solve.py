"""Quasi-static Tresca friction with stabilised Crouzeix-Raviart elements -- DOLFINx 0.11 solver.

Usage:  python scripts/dolfinx_solve.py SCENE.toml -o OUT.h5 [--refine k] [--steps N]
        mpirun -n 2 python scripts/dolfinx_solve.py SCENE.toml -o OUT.h5      (same answer)

Independent of the Rust crate and of scikit-fem; shares only ``tresca_scene.py`` (scene, mesh,
friction step, output) with ``skfem_solve.py``.  The discrete problem (README, Problem 2 of
Porwal & Wadhawan), written in UFL with the vector CR element ("CR", 1, (2,)):

    a_h(u, v) = int sigma(u):eps(v) dx
              + int_{dS} (2 rho mu / h_e) jump(u).jump(v) dS + int_{Gamma_D} (2 rho mu / h_e) u.v ds
                (both facet terms with the 2-point Gauss rule, h_e = FacetArea)
    (l^n, v)  = int f(t_n).v dx  (6-point Dunavant, custom rule) + int_{Gamma_N} g(t_n).v ds (3-point Gauss)
    u^n = argmin_v 1/2 a_h(v,v) - (l^n, v) + sum_{e in Gamma_C} |e| gbar_e |v_tau(m_e) - u^{n-1}_tau(m_e)|

Scene expressions are translated sympy -> UFL (x = SpatialCoordinate, t = a fem.Constant), so loads
are evaluated exactly at the quadrature points.  Parallel layout: matrices and load vectors are
assembled distributed (ghost contributions included), gathered to rank 0 in the canonical edge
ordering (edges matched by midpoint coordinates), and the small per-step friction problem is solved
on rank 0; true errors are assembled distributed again.
"""
import sys
import time

import numpy as np
import scipy.sparse as sp

from tresca_py import tresca_scene as ts  # noqa: E402

import dolfinx_solver  # noqa: E402,F401  (loads libmpi for the wheel; must precede dolfinx)
from mpi4py import MPI  # noqa: E402
import basix.ufl  # noqa: E402
import ufl  # noqa: E402
from dolfinx import fem  # noqa: E402
from dolfinx import mesh as dmesh  # noqa: E402


def sympy_to_ufl(expr, x, t, key="expression"):
    """Translate a sympy expression in x, y, t into UFL (x: SpatialCoordinate, t: Constant)."""
    import sympy
    rec = lambda e: sympy_to_ufl(e, x, t, key)  # noqa: E731
    if expr.is_Symbol:
        return {"x": x[0], "y": x[1], "t": t}[expr.name]
    if expr.is_number:
        return float(expr)
    if expr.is_Add:
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = out + rec(a)
        return out
    if expr.is_Mul:
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = out * rec(a)
        return out
    if expr.is_Pow:
        b, e = expr.args
        if e == sympy.Rational(1, 2):
            return ufl.sqrt(rec(b))
        return rec(b) ** (int(e) if e.is_Integer else rec(e))
    unary = {sympy.sin: ufl.sin, sympy.cos: ufl.cos, sympy.tan: ufl.tan, sympy.exp: ufl.exp,
             sympy.log: ufl.ln, sympy.Abs: abs, sympy.sign: ufl.sign, sympy.tanh: ufl.tanh,
             sympy.sinh: ufl.sinh, sympy.cosh: ufl.cosh}
    if expr.func in unary:
        return unary[expr.func](rec(expr.args[0]))
    if expr.func == sympy.atan2:
        return ufl.atan2(rec(expr.args[0]), rec(expr.args[1]))
    if isinstance(expr, sympy.Piecewise):
        # e.g. signum (see tresca_scene._signum); the last branch must be unconditional
        rel = {sympy.StrictLessThan: ufl.lt, sympy.LessThan: ufl.le, sympy.StrictGreaterThan: ufl.gt,
               sympy.GreaterThan: ufl.ge}
        out = None
        for val, cond in reversed(expr.args):
            if cond is sympy.true:
                out = rec(val)
            elif type(cond) in rel and out is not None:
                out = ufl.conditional(rel[type(cond)](rec(cond.args[0]), rec(cond.args[1])), rec(val), out)
            else:
                raise ts.SceneError(f"{key}: piecewise condition {cond} has no UFL equivalent")
        return out
    if expr.func in (sympy.Min, sympy.Max):
        op = ufl.min_value if expr.func == sympy.Min else ufl.max_value
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = op(out, rec(a))
        return out
    raise ts.SceneError(f"{key}: '{expr.func}' has no UFL equivalent (the dolfinx solver cannot use it)")


def vec_to_ufl(vexpr, x, t):
    return ufl.as_vector([sympy_to_ufl(c.sym, x, t, c.key) for c in vexpr.comps])


def dunavant_dx(msh):
    """The cell measure with the 6-point Dunavant rule (degree 4) of the Rust solver and scikit-fem."""
    return ufl.Measure("dx", domain=msh, metadata={
        "quadrature_rule": "custom", "quadrature_points": ts.DUNAVANT_REF_X.T.copy(),
        "quadrature_weights": ts.DUNAVANT_REF_W.copy()})


def error_forms(scene, uh, t, params, h, dS2, ds, dirichlet):
    """Compiled forms of the squared true errors of uh against the scene's exact solution: energy (with
    the jump terms on interior edges and on the Dirichlet part `dirichlet`, 2-point Gauss), H1 seminorm
    and L2, by the Dunavant rule. params = (lambda, mu, rho, 2 rho mu / h penalty on Gamma_D)."""
    lam, mu, rho, pen = params
    msh = uh.function_space.mesh
    X, dx4 = ufl.SpatialCoordinate(msh), dunavant_dx(msh)
    ue = vec_to_ufl(scene.exact_u, X, t)
    G = ufl.as_matrix([[sympy_to_ufl(scene.exact_grad[i][j].sym, X, t) for j in range(2)]
                       for i in range(2)]) - ufl.grad(uh)
    Es = ufl.sym(G)
    el = (lam * ufl.tr(Es) ** 2 + 2 * mu * ufl.inner(Es, Es)) * dx4
    # jump part of the energy error as an integral of squares (no cancellation)
    el = el + 2.0 * rho * mu / h("+") * ufl.inner(ufl.jump(uh), ufl.jump(uh)) * dS2
    if dirichlet:
        el = el + pen * ufl.inner(uh, uh) * ds(dirichlet, metadata={"quadrature_degree": 3})
    return [fem.form(el), fem.form(ufl.inner(G, G) * dx4), fem.form(ufl.inner(ue - uh, ue - uh) * dx4)]


def load_form(scene, msh, v, ds, t):
    """The load functional (l(t), v) as a compiled form (None without loads): the body force by the
    6-point Dunavant rule, tractions on Neumann part i (measure ds(i + 1)) by 3-point Gauss (degree 5)."""
    X = ufl.SpatialCoordinate(msh)
    dx4 = dunavant_dx(msh)
    L = None
    if not scene.f.is_zero:
        L = ufl.inner(vec_to_ufl(scene.f, X, t), v) * dx4
    for i, b in enumerate(scene.boundaries):
        if b.kind == "neumann" and not b.traction.is_zero:
            term = ufl.inner(vec_to_ufl(b.traction, X, t), v) * ds(i + 1, metadata={"quadrature_degree": 5})
            L = term if L is None else L + term
    return None if L is None else fem.form(L)


class DolfinxProblem:
    """Distributed assembly of a_h, its jump part, loads and true errors (canonical ordering on rank 0)."""

    def __init__(self, disc: ts.Discretisation, comm):
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
        edge = ts.match_points(disc.midpoints, xy, what="dolfinx CR dof coordinates")
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
        k = ts.match_points(disc.midpoints[bedges], bmid, what="dolfinx boundary facets")
        tags = disc.part_of_edge[bedges[k]] + 1
        order = np.argsort(bfacets)
        self.ft = dmesh.meshtags(msh, tdim - 1, bfacets[order], tags[order].astype(np.int32))
        ids = {kind: tuple(i + 1 for i, b in enumerate(scene.boundaries) if b.kind == kind)
               for kind in ("dirichlet", "neumann", "contact")}

        lam, mu, rho = scene.lam, scene.mu, scene.rho
        u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
        sigma = lambda w: lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2 * mu * eps(w)  # noqa: E731
        dx0 = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": 0})   # integrand is constant
        dS2 = ufl.Measure("dS", domain=msh, metadata={"quadrature_degree": 3})   # 2-point Gauss
        ds = ufl.Measure("ds", domain=msh, subdomain_data=self.ft)
        h = ufl.FacetArea(msh)
        pen = 2.0 * rho * mu / h
        a_el = ufl.inner(sigma(u), eps(v)) * dx0
        a_j = 2.0 * rho * mu / h("+") * ufl.inner(ufl.jump(u), ufl.jump(v)) * dS2
        if ids["dirichlet"]:
            a_j = a_j + pen * ufl.inner(u, v) * ds(ids["dirichlet"], metadata={"quadrature_degree": 3})
        self.J = self._gather_matrix(fem.form(a_j))
        Kel = self._gather_matrix(fem.form(a_el))
        self.K = None if rank else (Kel + self.J).tocsr()

        # loads: UFL expressions in x and the time constant t
        self.t = fem.Constant(msh, 0.0)
        self.L = load_form(scene, msh, v, ds, self.t)

        # true errors
        self.err_forms = None
        if scene.exact_u is not None:
            self.uh = fem.Function(V)
            self.err_forms = error_forms(scene, self.uh, self.t, (lam, mu, rho, pen), h, dS2, ds, ids["dirichlet"])

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
        self.t.value = t
        if self.L is None:
            vals = np.zeros(0)
            idx = np.zeros(0, dtype=np.int64)
        else:
            b = fem.assemble_vector(self.L)       # owned + ghost entries, ghosts not accumulated
            vals, idx = b.array.copy(), self.canon
        allv = self.comm.gather((idx, vals), root=0)
        if self.comm.rank:
            return None
        out = np.zeros(self.disc.n_dofs)
        for i, v in allv:
            np.add.at(out, i, v)
        return out

    def errors(self, t, u_canon):
        self.t.value = t
        self.uh.x.array[:] = u_canon[self.canon]
        loc = np.array([fem.assemble_scalar(f) for f in self.err_forms])
        tot = self.comm.allreduce(loc, op=MPI.SUM)
        return tuple(float(v) for v in tot)


def main(argv=None):
    comm = MPI.COMM_WORLD
    args = ts.cli(__doc__.splitlines()[0], argv)
    scene, disc, out = ts.open_scene(args)      # every rank reads the scene (deterministic)
    t0 = time.perf_counter()
    try:
        prob = DolfinxProblem(disc, comm)
    except ts.SceneError as err:
        sys.exit(f"error: {err}")
    t_asm = time.perf_counter() - t0
    errors = prob.errors if scene.exact_u is not None else None
    res = ts.run(disc, prob.K, prob.J, prob.load, errors, comm=comm, log=not args.quiet and comm.rank == 0)
    wall = time.perf_counter() - t0
    if comm.rank == 0:
        ts.write_results(out, disc, res, "dolfinx", {"assembly_time": t_asm, "total_time": wall,
                                                     "mpi_size": comm.size})
        print(f"dolfinx ({comm.size} rank{'s' if comm.size > 1 else ''}): {len(disc.edges)} edges, "
              f"{len(disc.contact)} contact edges, {len(scene.times) - 1} steps; "
              f"assembly+JIT {t_asm:.2f} s, total {wall:.2f} s -> {out}")


if __name__ == "__main__":
    main()

"""Boundary data of the distributed solver (issue 30, docs/scene.md): ``u = ["…", "…"]`` on a dirichlet part
imposes u = u_D(x, y, t) on Γ_D, ``gap = "…"`` on a contact part imposes u·n = g_n(x, y, t) on Γ_C, applied as
the Rust solver applies them (src/fem/lifting.rs):

* u = w + u_L, w in the constrained space of the rotated unknowns and u_L the CR function whose midpoint
  values are the edge means ū_D,e on Dirichlet edges and ḡ_e n_e on Γ_C edges (3-point Gauss, n_e outward),
  zero elsewhere;
* each step's right-hand side is lⁿ + b_D(tₙ; ·) − a_h(u_Lⁿ, ·) with b_D(t; v) = Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e u_D·v
  (3-point Gauss): the jump stabilisation on Dirichlet edges is measured against u_D;
* the energy written is Σ_T ∫σ(u):ε(u) + Σ_int (2ρμ/h_e)∫|[u]|² + Σ_D (2ρμ/h_e)∫|u − u_D|² (Rust's 2Eⁿ), and
  the energy error's jump on Γ_D is u_h − u (src/fem/norms.rs);
* data that do not fit together are refused (``consistency``).

The data are those of ``tresca_py.scene`` (``Boundary.u``/``.gap``), read there once for every solver.
"""
import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from tresca_py.dolfinx_cr.distributed.mesh import agree
from tresca_py.dolfinx_cr.forms import vec_to_ufl
from tresca_py.errors import InputError
from tresca_py.quadrature import GAUSS3_S, GAUSS3_W


def boundary_data(scene):
    """Per boundary part (scene order): (u_D as VecExpr or None, g_n as Expr or None; None when absent or the
    constant 0, ``tresca_py.scene``); None when no part gives data."""
    if not scene.has_boundary_data:
        return None
    return [(b.u, b.gap) for b in scene.boundaries]


def gauss_points(a, b):
    """(k, 3, 2): the 3-point Gauss points of the edges a[i]–b[i]."""
    return a[:, None, :] + GAUSS3_S[None, :, None] * (b - a)[:, None, :]


class Lifting:
    """u_L, the lifting's right-hand side form and the energy and error terms of a run with boundary data
    (module doc) on the owned edges of one rank. ``A``, ``B``: the owned edges' end points, ``pb``: their
    boundary parts."""

    def __init__(self, prob, data, A, B, pb):
        self.prob, self.data = prob, data
        self.d_blocks, self.d_points, self.d_expr = [], [], []
        self.g_pos, self.g_points, self.g_expr = [], [], []
        for ip, (u, g) in enumerate(data):
            if u is not None:
                sel = prob.dir_lb[pb[prob.dir_lb] == ip]
                self.d_blocks.append(sel)
                self.d_points.append(gauss_points(A[sel], B[sel]))
                self.d_expr.append(u)
            if g is not None:
                pos = np.flatnonzero(pb[prob.con_lb] == ip)
                self.g_pos.append(pos)
                self.g_points.append(gauss_points(A[prob.con_lb[pos]], B[prob.con_lb[pos]]))
                self.g_expr.append(g)
        self.uL = fem.Function(prob.V)
        self.t_set = None

    def set(self, t):
        """Collective: u_L at time t (edge means of the data; a value that is not finite stops every rank)."""
        self.prob.t.value = t
        if self.t_set == t:                    # set already at this time (the step's load)
            return
        arr = self.uL.x.array
        arr[:] = 0.0
        msg = None
        try:
            for blocks, q, u in zip(self.d_blocks, self.d_points, self.d_expr, strict=True):
                m = u(q[..., 0], q[..., 1], t) @ GAUSS3_W            # (2, k)
                arr[2 * blocks], arr[2 * blocks + 1] = m[0], m[1]
            for pos, q, g in zip(self.g_pos, self.g_points, self.g_expr, strict=True):
                m = g(q[..., 0], q[..., 1], t) @ GAUSS3_W
                blocks, n = self.prob.con_lb[pos], self.prob.normal[pos]
                arr[2 * blocks], arr[2 * blocks + 1] = m * n[:, 0], m * n[:, 1]
        except InputError as e:
            msg = str(e)
        agree(self.prob.comm, msg)
        self.uL.x.scatter_forward()
        self.t_set = t

    def compile(self, a_int, a_h, pen, ds):
        """The forms: rhs b_D − a_h(u_L, ·), the energy of u_h (module doc) and the Dirichlet jump of the energy
        error (u_h − u). ``a_int``: a_h without its Γ_D term, ``pen``: 2ρμ/h, ``ds``: the tagged measure."""
        prob, scene = self.prob, self.prob.scene
        msh, t, v, uh = prob.msh, prob.t, prob.v, prob.uh
        X = ufl.SpatialCoordinate(msh)
        ds5 = lambda i: ds(i + 1, metadata={"quadrature_degree": 5})  # noqa: E731  (3-point Gauss)
        ds3 = lambda i: ds(i + 1, metadata={"quadrature_degree": 3})  # noqa: E731  (2-point Gauss)
        rhs = -ufl.action(a_h, self.uL)
        energy = ufl.action(ufl.action(a_int, uh), uh)
        for i, (b, (u, _)) in enumerate(zip(scene.boundaries, self.data, strict=True)):
            if b.kind != "dirichlet":
                continue
            if u is None:
                energy = energy + pen * ufl.inner(uh, uh) * ds3(i)
                continue
            uD = vec_to_ufl(u, X, t)
            rhs = rhs + pen * ufl.inner(uD, v) * ds5(i)
            energy = energy + pen * ufl.inner(uh - uD, uh - uD) * ds5(i)
        self.rhs_form, self.energy_form = fem.form(rhs), fem.form(energy)
        self.err_form = None
        ids = tuple(i + 1 for i, b in enumerate(scene.boundaries) if b.kind == "dirichlet")
        if scene.exact_u is not None and ids:
            d = uh - vec_to_ufl(scene.exact_u, X, t)
            self.err_form = fem.form(pen * ufl.inner(d, d) * ds(ids, metadata={"quadrature_degree": 3}))

    def energy(self):
        """Collective: the energy of u_h (prob.uh, the real displacement)."""
        return self.prob.comm.allreduce(fem.assemble_scalar(self.energy_form), op=MPI.SUM)

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

The keys are read from the scene's text here (``boundary_data``), so this module does not depend on how
``tresca_py.scene`` stores them; ``load`` reads a scene whose keys ``tresca_py.scene`` does not know yet
(issue 30, branch pybdata) by setting them aside for the rest of the validation.
"""
import tomllib

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI

from tresca_py import scene as scene_mod
from tresca_py.dolfinx_cr.distributed.mesh import agree
from tresca_py.dolfinx_cr.forms import vec_to_ufl
from tresca_py.errors import InputError
from tresca_py.expr import Expr, VecExpr
from tresca_py.quadrature import GAUSS3_S, GAUSS3_W

DATA_KEYS = ("u", "gap")


def _tables(text):
    tables = tomllib.loads(text).get("boundary", [])
    return [b for b in tables if isinstance(b, dict)] if isinstance(tables, list) else []


def load(path, refine=None, steps=None):
    """The scene of ``path`` (``tresca_py.scene.load_scene``); a scene with boundary data is read with the
    keys ``u``/``gap`` set aside while ``tresca_py.scene`` does not know them (they are read by
    ``boundary_data``)."""
    known = scene_mod._SCHEMA["boundary"]
    try:
        with open(path, "rb") as fh:
            text = fh.read().decode("utf-8")
        tables = _tables(text)
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return scene_mod.load_scene(path, refine=refine, steps=steps)     # its error names the problem
    if all(k in known for k in DATA_KEYS) or not any(k in b for b in tables for k in DATA_KEYS):
        return scene_mod.load_scene(path, refine=refine, steps=steps)
    doc = tomllib.loads(text)
    for b in doc.get("boundary", []):
        for k in DATA_KEYS:
            if isinstance(b, dict):
                b.pop(k, None)
    return _load_doc(path, text, doc, refine, steps)


def _load_doc(path, text, doc, refine, steps):
    """``tresca_py.scene.load_scene`` on an already parsed document (its steps, in its order)."""
    sm = scene_mod
    for key, val in doc.items():                 # the checks of tresca_py.scene._read_doc
        if key not in sm._SCHEMA:
            raise sm.SceneError(f"{path}: unknown top-level key '{key}' (allowed: {sorted(sm._SCHEMA)})")
        allowed = sm._SCHEMA[key]
        if allowed is None:
            continue
        if key == "boundary" and not isinstance(val, list):
            raise sm.SceneError(f"{path}: 'boundary' must be an array of tables ([[boundary]])")
        for tab in (val if key == "boundary" else [val]):
            if not isinstance(tab, dict):
                raise sm.SceneError(f"{path}: [{key}] must be a table")
            bad = [k for k in tab if k not in allowed]
            if bad:
                raise sm.SceneError(f"{path}: unknown key '{bad[0]}' in [{key}] (allowed: {sorted(allowed)})")
    mesh = sm._read_mesh(path, doc, refine)
    E, nu = sm._read_material(path, doc)
    bnds = sm._read_boundaries(doc)
    rho = sm._num(doc.get("discretisation", {}), "rho", "discretisation", default=10.0)
    if rho <= 0:
        raise sm.SceneError("[discretisation] rho must be positive (without the jump term CR elasticity is singular)")
    solver = {"method": "ssn", "tol": 1e-12, "max_iter": 500, "uzawa_step": 0.0, **doc.get("solver", {})}
    exact_u, exact_grad = sm._read_exact(doc)
    return sm.Scene(path=str(path), text=text, title=str(doc.get("title", "")), mesh=mesh, E=float(E),
                    nu=float(nu), boundaries=bnds, f=VecExpr(doc.get("loads", {}).get("f", ["0", "0"]), "[loads] f"),
                    u0=VecExpr(doc.get("initial", {}).get("u0", ["0", "0"]), "[initial] u0"),
                    times=sm._read_times(path, doc, steps), rho=float(rho), solver=solver, exact_u=exact_u,
                    exact_grad=exact_grad, output=doc.get("output", {}).get("path"))


def boundary_data(scene):
    """Per boundary part (scene order): (u_D as VecExpr or None, g_n as Expr or None; None when absent or the
    constant 0, as src/scene/parts.rs); None when no part gives data. InputError for a key on the wrong kind
    of part."""
    out, any_data = [], False
    for b, tab in zip(scene.boundaries, _tables(scene.text), strict=True):
        u = g = None
        if "u" in tab:
            if b.kind != "dirichlet":
                raise InputError(f"[boundary] ('{b.name}') 'u' is only allowed for kind = \"dirichlet\"")
            u = VecExpr(tab["u"], f"boundary '{b.name}' u")
            u = None if u.is_zero else u                      # the constant 0 is no data (src/scene/parts.rs)
        if "gap" in tab:
            if b.kind != "contact":
                raise InputError(f"[boundary] ('{b.name}') 'gap' is only allowed for kind = \"contact\"")
            if not isinstance(tab["gap"], str):
                raise InputError(f"[boundary] ('{b.name}') 'gap' must be one expression string, got {tab['gap']!r}")
            g = Expr(tab["gap"], f"boundary '{b.name}' gap")
            g = None if g.is_zero else g
        any_data = any_data or u is not None or g is not None
        out.append((u, g))
    return out if any_data else None


def evaluate(expr, x, y, t):
    """expr(x, y, t) (Expr, or VecExpr: leading axis 2); InputError naming the expression where it is not
    finite, also where Python's float arithmetic raises instead (t enters as a float: 1/(t - 0.5) at 0.5)."""
    comps = getattr(expr, "comps", None)
    vals = []
    for c in comps or [expr]:
        try:
            vals.append(c(x, y, t))
        except ArithmeticError as e:
            raise InputError(f"{c.key}: expression {c.text!r} cannot be evaluated at t = {float(t):.6g}: {e}") from None
    return np.stack(vals) if comps is not None else vals[0]


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
                m = evaluate(u, q[..., 0], q[..., 1], t) @ GAUSS3_W            # (2, k)
                arr[2 * blocks], arr[2 * blocks + 1] = m[0], m[1]
            for pos, q, g in zip(self.g_pos, self.g_points, self.g_expr, strict=True):
                m = evaluate(g, q[..., 0], q[..., 1], t) @ GAUSS3_W
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

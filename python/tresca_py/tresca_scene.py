"""Shared, framework-free pieces of the independent Python solvers of tresca-cr.

This module knows nothing about scikit-fem or dolfinx. It provides

* ``load_scene``        -- read and validate a scene TOML file (README "Scenes"),
* ``structured_mesh`` / ``gmsh_mesh`` / ``red_refine`` -- the meshes the README specifies,
* ``Expr`` / ``VecExpr`` -- exmex expression strings in (x, y, t) translated with sympy,
* ``Discretisation``    -- edges, boundary parts, contact data, the CR interpolant u0,
* ``run``               -- backward Euler with an exact per-step friction solver,
* ``write_results``     -- the ``tresca`` HDF5 group of the README (plus ``tresca/energy``).

The mathematics
---------------
Unknowns are CR vector fields, one 2-vector per edge midpoint m_e, stored in the *canonical*
ordering ``2*e + c`` (edge e of ``Discretisation.edges``, component c). Dirichlet edges carry zero.
A contact edge e with outward normal n_e and tangent tau_e = (-n_y, n_x) carries u(m_e) = s_e tau_e.
The reduced space is parametrised by ``u = P r`` where r holds two numbers per free edge and one
number s_e per contact edge (listed last).  A framework script assembles, in the canonical ordering,

    K = a_h   (elasticity + jump stabilisation (2 rho mu / h_e) int_e [u].[v], 2-point Gauss)
    J = the jump part of a_h alone (for the energy error)
    l(t) = int f(t).v (6-point Dunavant) + int_{Gamma_N} g(t).v (3-point Gauss).

Backward Euler step n minimises  1/2 a_h(v,v) - (l^n, v) + sum_e w_e |s_e(v) - s_e^{n-1}|  with
w_e = |e| * mean_e(g_a).  Writing K_r = P^T K P, the optimality system is

    K_r r = P^T l - B mu,   mu_e in w_e * d|.|(s_e - s_e^{n-1}),   s = B^T r,

B selecting the contact unknowns.  Eliminating r (Z = K_r^{-1} B, C = B^T Z, s_free = B^T K_r^{-1} P^T l)
gives s = s_free - C mu and the box-constrained dual QP

    min_mu  1/2 mu^T C mu - mu^T d,   |mu_e| <= w_e,   d = s_free - s^{n-1},

solved exactly (to rounding) by a primal active-set method (finite, warm-started from the previous
step). Then r = K_r^{-1} P^T l - Z mu.  Tangential traction sigma_t,e = -mu_e / |e|; an edge slips
(state 1) when |mu_e| >= w_e (1 - 1e-9) and |ds_e| > 1e-9 * max(|ds|_inf, |d|_inf), ds = d - C mu (the
convention of the Rust solver, see ``classify``).
The initial value u^0 = I_CR u0 is the edge mean of u0 by 3-point Gauss (tau component on Gamma_C).
"""
from __future__ import annotations

import math
import os
import subprocess
import sys
import time
import tomllib
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

# ----------------------------------------------------------------------------------------------
# quadrature rules (fixed: they are part of the discrete problem)
# ----------------------------------------------------------------------------------------------
_A, _B = 0.445948490915964886, 0.091576213509770743
_WA, _WB = 0.223381589678011466, 0.109951743655321867
#: 6-point degree-4 Dunavant rule: barycentric coordinates (npts, 3) and weights summing to 1
DUNAVANT_BARY = np.array([[_A, _A, 1 - 2 * _A], [_A, 1 - 2 * _A, _A], [1 - 2 * _A, _A, _A],
                          [_B, _B, 1 - 2 * _B], [_B, 1 - 2 * _B, _B], [1 - 2 * _B, _B, _B]])
DUNAVANT_W = np.array([_WA] * 3 + [_WB] * 3)
#: reference-triangle version ((0,0),(1,0),(0,1)): points (2, 6), weights summing to 1/2
DUNAVANT_REF_X = DUNAVANT_BARY[:, 1:].T.copy()
DUNAVANT_REF_W = 0.5 * DUNAVANT_W
#: 3-point Gauss-Legendre on [0,1], weights summing to 1
GAUSS3_S = np.array([0.5 - 0.5 * math.sqrt(0.6), 0.5, 0.5 + 0.5 * math.sqrt(0.6)])
GAUSS3_W = np.array([5.0, 8.0, 5.0]) / 18.0


class SceneError(ValueError):
    """Invalid scene or mesh input; the message names the offending key or file."""


# ----------------------------------------------------------------------------------------------
# expressions (exmex syntax -> sympy -> numpy)
# ----------------------------------------------------------------------------------------------
_sympy = None


def _sp():
    global _sympy
    if _sympy is None:
        import sympy
        _sympy = sympy
    return _sympy


def _signum(a):
    """exmex's signum is Rust's f64::signum: +1 at 0 (sympy.sign(0) = 0 would disagree there)."""
    sympy = _sp()
    return sympy.Piecewise((-1, a < 0), (1, True))


def parse_expression(text, key="expression"):
    """Translate an exmex expression string in x, y, t into a sympy expression.

    ``^`` is power; constants PI/pi, E/e; functions sin cos tan exp ln log(=ln) sqrt abs signum tanh
    sinh cosh atan2 min max floor.  signum(0) = 1 as in exmex (Rust's f64::signum).  Anything else is rejected with an error naming ``key``.
    """
    sympy = _sp()
    from sympy.parsing.sympy_parser import parse_expr, standard_transformations
    if not isinstance(text, str) or not text.strip():
        raise SceneError(f"{key}: expected a non-empty expression string, got {text!r}")
    x, y, t = sympy.symbols("x y t", real=True)
    names = {
        "x": x, "y": y, "t": t, "PI": sympy.pi, "pi": sympy.pi, "E": sympy.E, "e": sympy.E,
        "sin": sympy.sin, "cos": sympy.cos, "tan": sympy.tan, "exp": sympy.exp,
        "ln": sympy.log, "log": sympy.log, "sqrt": sympy.sqrt, "abs": sympy.Abs,
        "signum": _signum, "tanh": sympy.tanh, "sinh": sympy.sinh, "cosh": sympy.cosh,
        "atan2": sympy.atan2, "min": sympy.Min, "max": sympy.Max, "floor": sympy.floor,
    }
    src = text.replace("^", "**")
    gdict = {"Integer": sympy.Integer, "Float": sympy.Float, "Rational": sympy.Rational,
             "Symbol": sympy.Symbol, "Function": sympy.Function, "__builtins__": {}}
    try:
        expr = parse_expr(src, local_dict=names, global_dict=gdict,
                          transformations=standard_transformations, evaluate=True)
    except Exception as err:  # sympy raises many types
        raise SceneError(f"{key}: cannot parse expression {text!r}: {err}") from None
    if not isinstance(expr, sympy.Expr):
        raise SceneError(f"{key}: {text!r} is not a scalar expression")
    from sympy.core.function import AppliedUndef
    bad = expr.atoms(AppliedUndef)
    if bad:
        raise SceneError(f"{key}: unknown function(s) {sorted(str(b.func) for b in bad)} in {text!r}")
    extra = expr.free_symbols - {x, y, t}
    if extra:
        raise SceneError(f"{key}: unknown variable(s) {sorted(map(str, extra))} in {text!r} "
                         "(only x, y, t are allowed)")
    return expr


class Expr:
    """A scalar expression of (x, y, t): ``.sym`` (sympy), ``__call__`` (numpy, broadcasting)."""

    def __init__(self, text, key="expression"):
        sympy = _sp()
        self.text, self.key = str(text), key
        self.sym = parse_expression(text, key)
        self.symbols = sympy.symbols("x y t", real=True)
        self._f = sympy.lambdify(self.symbols, self.sym, modules="numpy")

    @property
    def is_zero(self):
        return self.sym == 0

    @property
    def depends_on_t(self):
        return self.symbols[2] in self.sym.free_symbols

    def __call__(self, x, y, t):
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        with np.errstate(all="ignore"):
            val = np.asarray(self._f(x, y, float(t)), dtype=float)
        val = np.broadcast_to(val, np.broadcast(x, y).shape).copy()
        if not np.all(np.isfinite(val)):
            raise SceneError(f"{self.key}: expression {self.text!r} is not finite at t={t}")
        return val


class VecExpr:
    """A 2-vector of ``Expr``; ``__call__`` returns an array with leading axis 2."""

    def __init__(self, texts, key):
        if not isinstance(texts, (list, tuple)) or len(texts) != 2:
            raise SceneError(f"{key}: expected a list of two expression strings, got {texts!r}")
        self.comps = [Expr(s, f"{key}[{i}]") for i, s in enumerate(texts)]

    @property
    def is_zero(self):
        return all(c.is_zero for c in self.comps)

    @property
    def depends_on_t(self):
        return any(c.depends_on_t for c in self.comps)

    def __call__(self, x, y, t):
        return np.stack([c(x, y, t) for c in self.comps])


# ----------------------------------------------------------------------------------------------
# scene
# ----------------------------------------------------------------------------------------------
_SCHEMA = {
    "title": None,
    "mesh": {"corners", "cells", "diagonal", "refine", "file"},
    "material": {"E", "nu"},
    "boundary": {"name", "kind", "traction", "g_a"},
    "loads": {"f"},
    "initial": {"u0"},
    "time": {"T", "steps", "times"},
    "discretisation": {"rho"},
    "solver": {"method", "tol", "max_iter", "uzawa_step"},
    "exact": {"u", "grad"},
    "output": {"path"},
    "units": {"length", "force", "time"},  # labels for pictures only (scripts/render.py)
}


@dataclass
class Boundary:
    name: str
    kind: str                    # "dirichlet" | "neumann" | "contact"
    traction: VecExpr | None = None
    g_a: Expr | None = None


@dataclass
class Scene:
    path: str
    text: str
    title: str
    mesh: dict
    E: float
    nu: float
    boundaries: list
    f: VecExpr
    u0: VecExpr
    times: np.ndarray
    rho: float
    solver: dict
    exact_u: VecExpr | None = None
    exact_grad: list | None = None       # [[Expr, Expr], [Expr, Expr]]
    output: str | None = None

    @property
    def lam(self):
        return self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu))

    @property
    def mu(self):
        return self.E / (2 * (1 + self.nu))


def _num(tab, key, where, default=None, positive=False, integer=False):
    if key not in tab:
        if default is None:
            raise SceneError(f"[{where}] is missing the key '{key}'")
        return default
    v = tab[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or (integer and not isinstance(v, int)):
        raise SceneError(f"[{where}] {key} = {v!r}: expected {'an integer' if integer else 'a number'}")
    if not math.isfinite(v):
        raise SceneError(f"[{where}] {key} must be finite")
    if positive and v <= 0:
        raise SceneError(f"[{where}] {key} = {v!r} must be positive")
    return v


def load_scene(path, refine=None, steps=None):
    """Read and validate a scene TOML file. ``refine``/``steps`` override [mesh] refine / [time] steps."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except OSError as err:
        raise SceneError(f"cannot read scene file {path!r}: {err.strerror}") from None
    text = raw.decode("utf-8")
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise SceneError(f"{path}: invalid TOML: {err}") from None
    for key, val in doc.items():
        if key not in _SCHEMA:
            raise SceneError(f"{path}: unknown top-level key '{key}' (allowed: {sorted(_SCHEMA)})")
        allowed = _SCHEMA[key]
        tabs = val if key == "boundary" else [val]
        if allowed is None:
            continue
        if key == "boundary" and not isinstance(val, list):
            raise SceneError(f"{path}: 'boundary' must be an array of tables ([[boundary]])")
        for tab in tabs:
            if not isinstance(tab, dict):
                raise SceneError(f"{path}: [{key}] must be a table")
            for k in tab:
                if k not in allowed:
                    raise SceneError(f"{path}: unknown key '{k}' in [{key}] (allowed: {sorted(allowed)})")

    # mesh
    mesh = dict(doc.get("mesh", {}))
    if not mesh:
        raise SceneError(f"{path}: missing [mesh]")
    if "file" in mesh:
        if "corners" in mesh or "cells" in mesh or "diagonal" in mesh:
            raise SceneError(f"{path}: [mesh] takes either 'file' or 'corners'/'cells'/'diagonal', not both")
        fpath = mesh["file"]
        if not os.path.isabs(fpath):
            fpath = os.path.join(os.path.dirname(os.path.abspath(path)), fpath)
        mesh["file"] = fpath
    else:
        c = mesh.get("corners")
        if (not isinstance(c, list) or len(c) != 4 or
                any(not isinstance(p, list) or len(p) != 2 or
                    any(isinstance(q, bool) or not isinstance(q, (int, float)) for q in p) for p in c)):
            raise SceneError(f"{path}: [mesh] corners must be four [x, y] pairs, got {c!r}")
        cells = mesh.get("cells")
        if (not isinstance(cells, list) or len(cells) != 2 or
                any(isinstance(q, bool) or not isinstance(q, int) or q < 1 for q in cells)):
            raise SceneError(f"{path}: [mesh] cells must be two positive integers, got {cells!r}")
        diag = mesh.get("diagonal", "first")
        if diag not in ("first", "second"):
            raise SceneError(f"{path}: [mesh] diagonal must be \"first\" or \"second\", got {diag!r}")
        mesh["diagonal"] = diag
    mesh["refine"] = _num(mesh, "refine", "mesh", default=0, integer=True)
    if refine is not None:
        mesh["refine"] = int(refine)
    if mesh["refine"] < 0:
        raise SceneError(f"{path}: [mesh] refine must be >= 0")

    mat = doc.get("material")
    if not isinstance(mat, dict):
        raise SceneError(f"{path}: missing [material]")
    E = _num(mat, "E", "material", positive=True)
    nu = _num(mat, "nu", "material")
    if not (-1.0 < nu < 0.5):
        raise SceneError(f"[material] nu = {nu} must lie in (-1, 0.5)")

    bnds = []
    seen = set()
    for i, b in enumerate(doc.get("boundary", [])):
        where = f"boundary #{i + 1}"
        name, kind = b.get("name"), b.get("kind")
        if not isinstance(name, str):
            raise SceneError(f"[{where}] needs a string 'name'")
        if name in seen:
            raise SceneError(f"[{where}] boundary part '{name}' is declared twice")
        seen.add(name)
        if kind not in ("dirichlet", "neumann", "contact"):
            raise SceneError(f"[{where}] ('{name}') kind must be dirichlet, neumann or contact, got {kind!r}")
        if "traction" in b and kind != "neumann":
            raise SceneError(f"[{where}] ('{name}') 'traction' is only allowed for kind = \"neumann\"")
        if "g_a" in b and kind != "contact":
            raise SceneError(f"[{where}] ('{name}') 'g_a' is only allowed for kind = \"contact\"")
        bd = Boundary(name, kind)
        if kind == "neumann":
            bd.traction = VecExpr(b.get("traction", ["0", "0"]), f"boundary '{name}' traction")
        if kind == "contact":
            if "g_a" not in b:
                raise SceneError(f"[{where}] ('{name}') contact needs 'g_a' (the friction bound)")
            bd.g_a = Expr(b["g_a"], f"boundary '{name}' g_a")
            if bd.g_a.depends_on_t:
                raise SceneError(f"boundary '{name}' g_a must not depend on t")
        bnds.append(bd)

    loads = doc.get("loads", {})
    f = VecExpr(loads.get("f", ["0", "0"]), "[loads] f")
    u0 = VecExpr(doc.get("initial", {}).get("u0", ["0", "0"]), "[initial] u0")

    tm = doc.get("time")
    if not isinstance(tm, dict):
        raise SceneError(f"{path}: missing [time]")
    if "times" in tm:
        if "steps" in tm or "T" in tm:
            raise SceneError("[time] takes either 'times' or 'T' + 'steps', not both")
        times = np.asarray(tm["times"], dtype=float)
        if times.ndim != 1 or len(times) < 2 or np.any(np.diff(times) <= 0):
            raise SceneError("[time] times must be an increasing list of at least two numbers")
        if steps is not None:
            times = np.linspace(times[0], times[-1], int(steps) + 1)
    else:
        T = _num(tm, "T", "time", positive=True)
        N = _num(tm, "steps", "time", integer=True)
        if steps is not None:
            N = int(steps)
        if N < 1:
            raise SceneError("[time] steps must be >= 1")
        times = T * np.arange(N + 1) / N

    rho = _num(doc.get("discretisation", {}), "rho", "discretisation", default=10.0)
    if rho <= 0:
        raise SceneError("[discretisation] rho must be positive (without the jump term CR elasticity is singular)")
    solver = {"method": "ssn", "tol": 1e-12, "max_iter": 500, "uzawa_step": 0.0}
    solver.update(doc.get("solver", {}))

    exact_u = exact_grad = None
    if "exact" in doc:
        ex = doc["exact"]
        if "u" not in ex or "grad" not in ex:
            raise SceneError("[exact] needs both 'u' and 'grad'")
        exact_u = VecExpr(ex["u"], "[exact] u")
        g = ex["grad"]
        if not isinstance(g, list) or len(g) != 2 or any(not isinstance(r, list) or len(r) != 2 for r in g):
            raise SceneError("[exact] grad must be [[du1/dx, du1/dy], [du2/dx, du2/dy]]")
        exact_grad = [[Expr(g[i][j], f"[exact] grad[{i}][{j}]") for j in range(2)] for i in range(2)]
    out = doc.get("output", {}).get("path")
    return Scene(path=str(path), text=text, title=str(doc.get("title", "")), mesh=mesh, E=float(E),
                 nu=float(nu), boundaries=bnds, f=f, u0=u0, times=times, rho=float(rho), solver=solver,
                 exact_u=exact_u, exact_grad=exact_grad, output=out)


# ----------------------------------------------------------------------------------------------
# meshes
# ----------------------------------------------------------------------------------------------
@dataclass
class Mesh:
    points: np.ndarray               # (P, 2)
    triangles: np.ndarray            # (T, 3) counter-clockwise
    boundary_segments: dict = field(default_factory=dict)   # name -> (k, 2) vertex pairs


def structured_mesh(corners, n, m, diagonal="first"):
    """Structured triangulation of the quadrilateral c0 c1 c2 c3 (README).

    p(i,j) = bilinear map of (i/n, j/m); index j*(n+1)+i.  Cell (i,j) is split along
    p(i,j)-p(i+1,j+1) ("first") or p(i+1,j)-p(i,j+1) ("second").  Sides: bottom (j=0), right (i=n),
    top (j=m), left (i=0).
    """
    c = np.asarray(corners, dtype=float)
    xi = np.arange(n + 1) / n
    eta = np.arange(m + 1) / m
    X, Y = np.meshgrid(xi, eta)            # (m+1, n+1): index [j, i]
    X, Y = X.ravel()[:, None], Y.ravel()[:, None]
    pts = ((1 - X) * (1 - Y) * c[0] + X * (1 - Y) * c[1] + X * Y * c[2] + (1 - X) * Y * c[3])

    def idx(i, j):
        return j * (n + 1) + i

    Ii, Jj = np.meshgrid(np.arange(n), np.arange(m))
    Ii, Jj = Ii.ravel(), Jj.ravel()
    p00, p10, p11, p01 = idx(Ii, Jj), idx(Ii + 1, Jj), idx(Ii + 1, Jj + 1), idx(Ii, Jj + 1)
    if diagonal == "first":
        tri = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:
        tri = np.stack([np.stack([p00, p10, p01], 1), np.stack([p10, p11, p01], 1)], 1)
    tri = tri.reshape(-1, 3)
    i_n, j_m = np.arange(n), np.arange(m)
    segs = {
        "bottom": np.stack([idx(i_n, 0), idx(i_n + 1, 0)], 1),
        "right": np.stack([idx(n, j_m), idx(n, j_m + 1)], 1),
        "top": np.stack([idx(i_n + 1, m), idx(i_n, m)], 1),
        "left": np.stack([idx(0, j_m + 1), idx(0, j_m)], 1),
    }
    return Mesh(pts, tri.astype(np.int64), segs)


def red_refine(mesh: Mesh) -> Mesh:
    """Split every triangle into four through its edge midpoints; boundary segments are halved."""
    tri = mesh.triangles
    P = len(mesh.points)
    pairs = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    uniq, inv = np.unique(pairs, axis=0, return_inverse=True)
    inv = inv.ravel()
    mids = 0.5 * (mesh.points[uniq[:, 0]] + mesh.points[uniq[:, 1]])
    nt = len(tri)
    m01, m12, m20 = P + inv[:nt], P + inv[nt:2 * nt], P + inv[2 * nt:]
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    new = np.concatenate([np.stack([a, m01, m20], 1), np.stack([m01, b, m12], 1),
                          np.stack([m20, m12, c], 1), np.stack([m01, m12, m20], 1)])
    lookup = {tuple(p): P + k for k, p in enumerate(uniq)}
    segs = {}
    for name, s in mesh.boundary_segments.items():
        mid = np.array([lookup[tuple(sorted(e))] for e in s.tolist()], dtype=np.int64).reshape(-1)
        segs[name] = np.concatenate([np.stack([s[:, 0], mid], 1), np.stack([mid, s[:, 1]], 1)]) \
            if len(s) else s
    return Mesh(np.vstack([mesh.points, mids]), new.astype(np.int64), segs)


def gmsh_mesh(path) -> Mesh:
    """Read a Gmsh 4.1 mesh with meshio: triangles, and 1D physical groups naming boundary parts."""
    import meshio
    try:
        msh = meshio.read(path, file_format="gmsh")
    except FileNotFoundError:
        raise SceneError(f"mesh file {path!r} does not exist") from None
    except Exception as err:
        raise SceneError(f"cannot read Gmsh mesh {path!r}: {err}") from None
    tris, lines, line_tags = [], [], []
    phys = msh.cell_data.get("gmsh:physical")
    for k, block in enumerate(msh.cells):
        if block.type == "triangle":
            tris.append(block.data)
        elif block.type == "line":
            lines.append(block.data)
            if phys is None:
                raise SceneError(f"{path}: line elements carry no physical tags")
            line_tags.append(np.asarray(phys[k]))
        elif block.type in ("vertex",):
            continue
        else:
            raise SceneError(f"{path}: unsupported element type '{block.type}' (only linear triangles and lines)")
    if not tris:
        raise SceneError(f"{path}: no triangles")
    tri = np.concatenate(tris).astype(np.int64)
    pts = np.asarray(msh.points[:, :2], dtype=float)
    if msh.points.shape[1] > 2 and np.any(np.abs(msh.points[:, 2]) > 1e-14):
        raise SceneError(f"{path}: mesh is not planar (z != 0)")
    used = np.unique(tri)
    renum = -np.ones(len(pts), dtype=np.int64)
    renum[used] = np.arange(len(used))
    pts, tri = pts[used], renum[tri]
    d = pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]]
    area2 = d[0][:, 0] * d[1][:, 1] - d[0][:, 1] * d[1][:, 0]
    tri[area2 < 0] = tri[area2 < 0][:, [0, 2, 1]]
    names = {}
    for name, (tag, dim) in msh.field_data.items():
        if int(dim) == 1:
            names[int(tag)] = name
    segs = {}
    if lines:
        L = np.concatenate(lines).astype(np.int64)
        T = np.concatenate(line_tags)
        if np.any(renum[L] < 0):
            raise SceneError(f"{path}: a boundary line uses a node that belongs to no triangle")
        L = renum[L]
        for tag in np.unique(T):
            if int(tag) == 0:          # lines outside any physical group name no boundary part
                continue
            if int(tag) not in names:
                raise SceneError(f"{path}: physical line tag {tag} has no name")
            segs[names[int(tag)]] = L[T == tag]
    return Mesh(pts, tri, segs)


def build_mesh(scene: Scene) -> Mesh:
    ms = scene.mesh
    if "file" in ms:
        mesh = gmsh_mesh(ms["file"])
        for _ in range(ms["refine"]):
            mesh = red_refine(mesh)
        return mesh
    k = 2 ** ms["refine"]
    return structured_mesh(ms["corners"], ms["cells"][0] * k, ms["cells"][1] * k, ms["diagonal"])


# ----------------------------------------------------------------------------------------------
# discretisation data shared by both solvers
# ----------------------------------------------------------------------------------------------
class Discretisation:
    """Edges, boundary parts and contact data of a scene on its mesh (framework independent).

    Attributes: ``points, triangles, edges (E,2), midpoints, lengths, edge_tris (E,2; -1 = none),
    part_of_edge (E,; -1 interior)``, per kind the edge index arrays ``dirichlet, neumann (dict
    part -> edges), contact`` and for the contact edges ``normal, tangent, gbar, weight = |e| gbar``.
    Boundary edges are stored counter-clockwise (interior on the left), so tangent = direction.
    """

    def __init__(self, scene: Scene, mesh: Mesh | None = None):
        self.scene = scene
        mesh = build_mesh(scene) if mesh is None else mesh
        self.points, self.triangles = mesh.points, mesh.triangles
        p, tri = self.points, self.triangles
        d1, d2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
        area2 = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        if np.any(area2 <= 1e-14 * np.max(np.abs(area2))):
            raise SceneError("mesh has degenerate or clockwise triangles (check the corner order)")
        self.areas = 0.5 * area2
        loc = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])   # oriented
        key = np.sort(loc, axis=1)
        edges, inv, cnt = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        inv = inv.ravel()
        if np.any(cnt > 2):
            raise SceneError("mesh is not a manifold: an edge is shared by more than two triangles")
        nt = len(tri)
        self.tri_edges = inv.reshape(3, nt).T.copy()          # edge k = (v_k, v_{k+1})
        E = len(edges)
        bnd = cnt == 1
        edges[inv[bnd[inv]]] = loc[bnd[inv]]                   # boundary edges counter-clockwise
        self.edges = edges.astype(np.int64)
        self.edge_tris = -np.ones((E, 2), dtype=np.int64)
        owner = np.tile(np.arange(nt), 3)
        order = np.argsort(inv, kind="stable")
        first = np.ones(len(order), bool)
        first[1:] = inv[order][1:] != inv[order][:-1]
        self.edge_tris[inv[order][first], 0] = owner[order][first]
        self.edge_tris[inv[order][~first], 1] = owner[order][~first]
        self.midpoints = 0.5 * (p[self.edges[:, 0]] + p[self.edges[:, 1]])
        dvec = p[self.edges[:, 1]] - p[self.edges[:, 0]]
        self.lengths = np.hypot(dvec[:, 0], dvec[:, 1])
        self.is_boundary = bnd

        # boundary parts
        self.part_of_edge = -np.ones(E, dtype=np.int64)
        lookup = {(int(a), int(b)): k for k, (a, b) in enumerate(np.sort(self.edges, axis=1))}
        parts = {b.name: b for b in scene.boundaries}
        for name in parts:
            if name not in mesh.boundary_segments:
                avail = sorted(mesh.boundary_segments)
                raise SceneError(f"boundary part '{name}' does not exist in the mesh (available: {avail})")
        for ip, b in enumerate(scene.boundaries):
            segs = mesh.boundary_segments[b.name]
            for a, c in segs.tolist():
                k = lookup.get((min(a, c), max(a, c)))
                if k is None:
                    raise SceneError(f"boundary part '{b.name}': segment ({a},{c}) is not a mesh edge")
                if not bnd[k]:
                    raise SceneError(f"boundary part '{b.name}' contains an interior edge")
                if self.part_of_edge[k] >= 0:
                    other = scene.boundaries[self.part_of_edge[k]].name
                    raise SceneError(f"boundary edge at {self.midpoints[k]} belongs to both '{other}' and '{b.name}'")
                self.part_of_edge[k] = ip
        missing = np.flatnonzero(bnd & (self.part_of_edge < 0))
        if len(missing):
            unnamed = [n for n in mesh.boundary_segments if n not in parts]
            raise SceneError(f"{len(missing)} boundary edge(s) belong to no [[boundary]] part, e.g. the edge "
                             f"with midpoint {self.midpoints[missing[0]].tolist()} (undeclared mesh parts: {unnamed})")
        kinds = np.array([b.kind for b in scene.boundaries] + ["interior"])
        kind_of_edge = kinds[self.part_of_edge]
        self.dirichlet = np.flatnonzero(kind_of_edge == "dirichlet")
        self.contact = np.flatnonzero(kind_of_edge == "contact")
        self.neumann = {b.name: np.flatnonzero(self.part_of_edge == ip)
                        for ip, b in enumerate(scene.boundaries) if b.kind == "neumann"}
        self.interior = np.flatnonzero(~bnd)
        if len(self.dirichlet) == 0:
            # with the jump term a_h is still definite only if rigid motions are excluded
            print("warning: no Dirichlet edges; a_h may be singular", file=sys.stderr)

        c = self.contact
        dv = dvec[c] / self.lengths[c, None]
        self.tangent = dv                                       # counter-clockwise direction
        self.normal = np.stack([dv[:, 1], -dv[:, 0]], 1)        # outward: tau = (-n_y, n_x)
        self.gbar = np.zeros(len(c))
        for ip, b in enumerate(scene.boundaries):
            if b.kind != "contact":
                continue
            sel = self.part_of_edge[c] == ip
            xq, yq = self.edge_points(c[sel])
            g = b.g_a(xq, yq, 0.0)
            if np.any(g < 0):
                raise SceneError(f"boundary '{b.name}': g_a is negative somewhere")
            self.gbar[sel] = g @ GAUSS3_W
        self.weight = self.lengths[c] * self.gbar

    @property
    def n_dofs(self):
        return 2 * len(self.edges)

    def edge_points(self, edges):
        """3-point Gauss points on the given edges: x, y arrays of shape (len(edges), 3)."""
        a = self.points[self.edges[edges, 0]]
        b = self.points[self.edges[edges, 1]]
        q = a[:, None, :] + GAUSS3_S[None, :, None] * (b - a)[:, None, :]
        return q[..., 0], q[..., 1]

    def interpolate(self, vexpr: VecExpr, t=0.0):
        """CR interpolant (edge means, 3-point Gauss) in the constrained space, canonical ordering."""
        xq, yq = self.edge_points(np.arange(len(self.edges)))
        vals = vexpr(xq, yq, t) @ GAUSS3_W                      # (2, E)
        u = vals.T.copy()
        u[self.dirichlet] = 0.0
        s = np.sum(u[self.contact] * self.tangent, axis=1)
        u[self.contact] = s[:, None] * self.tangent
        return u.ravel()

    def reduction(self):
        """Sparse P (2E x nred) with u_full = P r; contact unknowns s_e are the last C entries of r."""
        E = len(self.edges)
        free = np.ones(E, bool)
        free[self.dirichlet] = False
        free[self.contact] = False
        fe = np.flatnonzero(free)
        nf = 2 * len(fe)
        C = len(self.contact)
        rows = np.concatenate([2 * fe, 2 * fe + 1, 2 * self.contact, 2 * self.contact + 1])
        cols = np.concatenate([2 * np.arange(len(fe)), 2 * np.arange(len(fe)) + 1,
                               nf + np.arange(C), nf + np.arange(C)])
        vals = np.concatenate([np.ones(nf), self.tangent[:, 0], self.tangent[:, 1]])
        P = sp.csr_matrix((vals, (rows, cols)), shape=(2 * E, nf + C))
        return P, nf + np.arange(C)


def match_points(ref, other, tol=1e-9, what="points"):
    """Index array ``idx`` with ``other[i] == ref[idx[i]]`` (nearest neighbour, checked to ``tol``)."""
    from scipy.spatial import cKDTree
    scale = max(1.0, float(np.max(np.abs(ref))) if len(ref) else 1.0)
    dist, idx = cKDTree(ref).query(other)
    if len(dist) and np.max(dist) > tol * scale:
        i = int(np.argmax(dist))
        raise ValueError(f"cannot match {what}: {other[i]} has no partner (distance {dist[i]:.3e})")
    return idx


# ----------------------------------------------------------------------------------------------
# the per-step friction problem
# ----------------------------------------------------------------------------------------------
def box_qp(C, d, w, mu0=None, max_iter=None):
    """Exact solution of min 1/2 mu^T C mu - mu^T d subject to |mu_i| <= w_i (C SPD, small, dense).

    Primal active-set method: every iterate is feasible, a bound is dropped only at a minimiser of
    the current face, and the objective decreases strictly, so no face repeats (finite termination).
    Returns (mu, iterations).
    """
    n = len(d)
    if n == 0:
        return np.zeros(0), 0
    max_iter = max_iter or 10 * n + 50
    mu = np.zeros(n) if mu0 is None else np.clip(mu0, -w, w)
    upper = (mu >= w)                      # fixed at +w (w == 0 counts as fixed)
    lower = (mu <= -w) & ~upper
    fixed = upper | lower
    gscale = np.max(np.abs(d)) + np.max(np.abs(C)) * np.max(w) + 1e-300
    for it in range(1, max_iter + 1):
        F = np.flatnonzero(~fixed)
        if len(F):
            rhs = d[F] - C[np.ix_(F, np.flatnonzero(fixed))] @ mu[fixed]
            target = np.linalg.solve(C[np.ix_(F, F)], rhs)
            p = target - mu[F]
            # ratio test against the box
            with np.errstate(divide="ignore", invalid="ignore"):
                lim = np.where(p > 0, (w[F] - mu[F]) / p, np.where(p < 0, (-w[F] - mu[F]) / p, np.inf))
            j = int(np.argmin(lim)) if len(lim) else -1
            if j >= 0 and lim[j] < 1.0:
                alpha = max(lim[j], 0.0)
                mu[F] += alpha * p
                k = F[j]
                if p[j] > 0:
                    mu[k], upper[k] = w[k], True
                else:
                    mu[k], lower[k] = -w[k], True
                fixed[k] = True
                continue
            mu[F] = target
        # multiplier (gradient) test on the fixed set
        g = C @ mu - d
        viol = np.zeros(n)
        viol[upper] = g[upper]              # at +w optimal iff g <= 0
        viol[lower] = -g[lower]             # at -w optimal iff g >= 0
        viol[w <= 0] = 0.0                  # w = 0: mu is pinned at 0
        k = int(np.argmax(viol))
        if viol[k] <= 1e-14 * gscale:
            return mu, it
        fixed[k] = upper[k] = lower[k] = False
    raise RuntimeError(f"box QP: no convergence in {max_iter} active-set iterations")


def kkt_residual(C, d, w, mu):
    """Natural residual |mu - P_box(mu - gamma (C mu - d))|_inf / max(w), gamma = 1/max diag C."""
    if len(mu) == 0:
        return 0.0
    gamma = 1.0 / max(np.max(np.diag(C)), 1e-300)
    r = mu - np.clip(mu - gamma * (C @ mu - d), -w, w)
    return float(np.max(np.abs(r)) / max(np.max(w), 1e-300))


class StepSolver:
    """Factorises K_r once and solves backward Euler steps exactly (see module docstring)."""

    def __init__(self, disc: Discretisation, K):
        self.disc = disc
        self.P, self.ic = disc.reduction()
        Kr = (self.P.T @ K @ self.P).tocsc()
        Kr = (0.5 * (Kr + Kr.T)).tocsc()
        self.Kr = Kr
        # K_r is SPD: symmetric minimum-degree ordering and diagonal pivots (SuperLU symmetric mode)
        self.lu = spla.splu(Kr, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                            options=dict(SymmetricMode=True))
        self.w = disc.weight
        C = len(self.ic)
        if C:
            B = np.zeros((Kr.shape[0], C))
            B[self.ic, np.arange(C)] = 1.0
            self.Z = self._solve(B)
            Cm = self.Z[self.ic, :]
            self.C = 0.5 * (Cm + Cm.T)
        else:
            self.Z = np.zeros((Kr.shape[0], 0))
            self.C = np.zeros((0, 0))
        self.mu = np.zeros(C)

    def _solve(self, b):
        x = self.lu.solve(b)
        x += self.lu.solve(b - self.Kr @ x)          # one step of iterative refinement
        return x

    def step(self, l_full, u_prev_full):
        """One backward Euler step; returns (u_full, info dict)."""
        disc = self.disc
        r_free = self._solve(self.P.T @ l_full)
        if len(self.ic) == 0:
            return self.P @ r_free, dict(iterations=1, residual=0.0, mu=np.zeros(0), d=np.zeros(0), ds=np.zeros(0))
        s_old = np.sum(u_prev_full.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
        d = r_free[self.ic] - s_old
        mu, its = box_qp(self.C, d, self.w, self.mu)
        self.mu = mu.copy()
        r = r_free - self.Z @ mu
        u = self.P @ r
        return u, dict(iterations=its, residual=kkt_residual(self.C, d, self.w, mu), mu=mu, d=d,
                       ds=d - self.C @ mu)


def classify(mu, ds, d, w):
    """Stick (0) / slip (1) per contact edge, the convention of the Rust solver (friction::classify):
    slip when |mu_e| >= w_e (1 - 1e-9) and |ds_e| > 1e-9 max(|ds|_inf, |d|_inf), where ds = d - C mu is
    the slip increment of the step and d = s_free - s^{n-1} the increment without friction
    (w_e = 0: slip when |ds_e| exceeds the threshold)."""
    if len(mu) == 0:
        return np.zeros(0, dtype=bool)
    scale = max(float(np.max(np.abs(ds))), float(np.max(np.abs(d))))
    return (np.abs(mu) >= w * (1 - 1e-9)) & (np.abs(ds) > 1e-9 * scale)


# ----------------------------------------------------------------------------------------------
# driver
# ----------------------------------------------------------------------------------------------
def run(disc: Discretisation, K, J, load, errors=None, comm=None, log=True):
    """Backward Euler over ``scene.times``.

    ``K``: canonical sparse a_h (only needed on rank 0); ``J`` (its jump part) is unused here.
    ``load(t)``: collective; canonical load vector on rank 0 (anything elsewhere).
    ``errors(t, u)``: collective, ``u`` canonical on every rank; returns (energy error^2, h1^2, l2^2)
    on rank 0, the energy error including the jump terms (2 rho mu/h_e) int_e |[u_h]|^2 computed by the
    framework as an integral of squares (u^T J u would lose sqrt(eps) accuracy when the jumps vanish).  Returns the results dict on rank 0, None elsewhere.
    """
    rank = 0 if comm is None else comm.rank
    scene = disc.scene
    times = scene.times
    N = len(times) - 1
    C = len(disc.contact)
    root = rank == 0
    if root:
        t0 = time.perf_counter()
        stepper = StepSolver(disc, K)
        t_fact = time.perf_counter() - t0
        E2 = disc.n_dofs
        res = dict(u=np.zeros((N + 1, E2 // 2, 2)), slip=np.zeros((N + 1, C)),
                   sigma_t=np.zeros((N + 1, C)), state=np.zeros((N + 1, C), dtype=np.int8),
                   iterations=np.zeros(N + 1, dtype=np.int64), residual=np.zeros(N + 1),
                   n_stick=np.zeros(N + 1, dtype=np.int64), n_slip=np.zeros(N + 1, dtype=np.int64),
                   wall_time=np.zeros(N + 1), energy=np.zeros(N + 1), factor_time=t_fact)
        if scene.exact_u is not None:
            res["errors"] = {k: np.zeros(N + 1) for k in ("energy", "h1", "l2")}
        u = disc.interpolate(scene.u0, times[0])
    else:
        u = None
    for n, t in enumerate(times):
        tic = time.perf_counter()
        if n > 0:
            load_t = load(t)
            if root:
                u_prev = u
                u, info = stepper.step(load_t, u_prev)
                mu = info["mu"]
                slip = classify(mu, info["ds"], info["d"], disc.weight)
                res["sigma_t"][n] = -mu / disc.lengths[disc.contact]
                res["state"][n] = slip
                res["iterations"][n] = info["iterations"]
                res["residual"][n] = info["residual"]
        if root:
            res["u"][n] = u.reshape(-1, 2)
            res["slip"][n] = np.sum(u.reshape(-1, 2)[disc.contact] * disc.tangent, axis=1)
            res["n_slip"][n] = int(res["state"][n].sum())
            res["n_stick"][n] = C - res["n_slip"][n]
            res["energy"][n] = float(u @ (K @ u))
        if scene.exact_u is not None and errors is not None:
            ub = u if comm is None else comm.bcast(u, root=0)
            e = errors(t, ub)
            if root:
                el, h1, l2 = e
                res["errors"]["energy"][n] = math.sqrt(max(el, 0.0))
                res["errors"]["h1"][n] = math.sqrt(max(h1, 0.0))
                res["errors"]["l2"][n] = math.sqrt(max(l2, 0.0))
        if root:
            res["wall_time"][n] = time.perf_counter() - tic
            if log and (n == N or (N >= 10 and n % max(1, N // 10) == 0)):
                extra = f" err_E={res['errors']['energy'][n]:.4e}" if "errors" in res else ""
                print(f"step {n:5d}/{N} t={t:.6g} iters={res['iterations'][n]} "
                      f"slip={res['n_slip'][n]}/{C} a_h(u,u)={res['energy'][n]:.6e}{extra}", flush=True)
    return res if root else None


# ----------------------------------------------------------------------------------------------
# output
# ----------------------------------------------------------------------------------------------
def _git_commit():
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              cwd=os.path.dirname(os.path.abspath(__file__)), timeout=5).stdout.strip() or "unknown"
    except Exception:
        return "unknown"


def write_results(path, disc: Discretisation, res, solver_name, extra_attrs=None):
    """Write the README ``tresca`` group (plus ``tresca/energy`` = a_h(u^n, u^n))."""
    import h5py
    scene = disc.scene
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with h5py.File(path, "w") as h5:
        g = h5.create_group("tresca")
        g.create_dataset("mesh/points", data=disc.points)
        g.create_dataset("mesh/triangles", data=disc.triangles)
        g.create_dataset("mesh/edges", data=disc.edges)
        g.create_dataset("mesh/midpoints", data=disc.midpoints)
        g.create_dataset("times", data=scene.times)
        g.create_dataset("u", data=res["u"])
        g.create_dataset("energy", data=res["energy"])
        g.create_dataset("contact/edges", data=disc.contact)
        g.create_dataset("contact/normal", data=disc.normal)
        g.create_dataset("contact/tangent", data=disc.tangent)
        g.create_dataset("contact/slip", data=res["slip"])
        g.create_dataset("contact/sigma_t", data=res["sigma_t"])
        g.create_dataset("contact/g", data=disc.gbar)
        g.create_dataset("contact/state", data=res["state"])
        for k in ("iterations", "residual", "n_stick", "n_slip", "wall_time"):
            g.create_dataset(f"steps/{k}", data=res[k])
        if "errors" in res:
            for k, v in res["errors"].items():
                g.create_dataset(f"errors/{k}", data=v)
        attrs = {"scene": scene.text, "scene_path": os.path.abspath(scene.path), "version": "python-1",
                 "git_commit": _git_commit(), "solver": solver_name,
                 "method": "primal active set on the condensed dual (exact)",
                 "tol": float(scene.solver.get("tol", 1e-12)), "rho": scene.rho, "E": scene.E, "nu": scene.nu,
                 "refine": int(scene.mesh["refine"]), "steps": len(scene.times) - 1,
                 "n_edges": len(disc.edges), "n_contact": len(disc.contact),
                 "factor_time": float(res.get("factor_time", 0.0))}
        attrs.update(extra_attrs or {})
        for k, v in attrs.items():
            g.attrs[k] = v


def cli(description, argv=None):
    """Common command line: SCENE.toml -o OUT.h5 [--refine k] [--steps N]."""
    import argparse
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("scene", help="scene TOML file")
    ap.add_argument("-o", "--output", help="results file (default: [output] path of the scene)")
    ap.add_argument("--refine", type=int, default=None, help="override [mesh] refine")
    ap.add_argument("--steps", type=int, default=None, help="override the number of uniform time steps")
    ap.add_argument("-q", "--quiet", action="store_true", help="no per-step log")
    args = ap.parse_args(argv)
    return args


def open_scene(args):
    """Load scene + discretisation, turning SceneError into a clean exit message."""
    try:
        scene = load_scene(args.scene, refine=args.refine, steps=args.steps)
        out = args.output or scene.output
        if not out:
            raise SceneError("no output path: give -o OUT.h5 or [output] path in the scene")
        disc = Discretisation(scene)
    except SceneError as err:
        sys.exit(f"error: {err}")
    return scene, disc, out

"""Scene files (README "Scenes"): TOML reading and validation, as src/scene does it.

Unknown tables and keys are errors naming them; fixed-length arrays (corners, cells, every vector of
expressions, grad) must have exactly their length, like the Rust reader's serde arrays
(``cells = [2, 2, 2]`` is refused). Expressions are read by ``tresca_py.expr``.
"""
from __future__ import annotations

import math
import os
import tomllib
from dataclasses import dataclass

import numpy as np

from tresca_py.elastic import lame
from tresca_py.errors import InputError
from tresca_py.expr import Expr, VecExpr


class SceneError(InputError):
    """Invalid scene input; the message names the offending key or file."""


_SCHEMA = {
    "title": None,
    "mesh": {"corners", "cells", "diagonal", "refine", "file"},
    "material": {"E", "nu"},
    "boundary": {"name", "kind", "traction", "g_a", "u", "gap", "law", "coulomb"},
    "loads": {"f"},
    "initial": {"u0"},
    "time": {"T", "steps", "times"},
    "discretisation": {"rho"},
    "solver": {"method", "tol", "max_iter", "uzawa_step"},
    "exact": {"u", "grad"},
    "output": {"path"},
    "units": {"length", "force", "time"},  # labels for pictures only (scripts/render.py)
    # what `tresca-cr study` estimates
    "outputs": {"max_slip", "stick_length", "contact_length", "max_pressure", "energy", "traction_at"},
}


@dataclass
class Boundary:
    name: str
    kind: str                    # "dirichlet" | "neumann" | "contact" (a symmetry part is a contact part)
    traction: VecExpr | None = None   # Neumann traction, or the given surface load on Γ_C (None: none)
    g_a: Expr | None = None      # Tresca's bound (None with coulomb)
    u: VecExpr | None = None     # Dirichlet data u_D(x, y, t); None: clamped (absent or the constant 0)
    gap: Expr | None = None      # imposed normal displacement g_n(x, y, t) on Γ_C, or the gap; None: 0
    law: str = "bilateral"       # contact law: "bilateral" (u.n = g_n) or "unilateral" (u.n <= g)
    coulomb: Expr | None = None  # Coulomb's coefficient F(x, y): threshold F p
    symmetry: bool = False       # written kind = "symmetry": frictionless bilateral, u.n = 0

    @property
    def has_data(self):
        """True if the part imposes nonzero boundary data (u_D or g_n)."""
        return self.u is not None or self.gap is not None


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
    def normal_unknowns(self):
        """True if every Γ_C edge carries a normal unknown: the scene has a unilateral or a Coulomb part."""
        return any(b.kind == "contact" and (b.law == "unilateral" or b.coulomb is not None) for b in self.boundaries)

    def refuse_contact_extensions(self, solver):
        """SceneError naming the part if the scene uses what ``solver`` does not model (issue 40: a unilateral
        law, Coulomb friction, a surface load on Γ_C)."""
        for b in self.boundaries:
            if b.kind == "contact" and (b.law == "unilateral" or b.coulomb is not None or b.traction is not None):
                raise SceneError(f"boundary '{b.name}': the {solver} solver models bilateral Tresca contact only "
                                 "(no law = \"unilateral\", coulomb or contact traction)")

    @property
    def has_boundary_data(self):
        """True if a part imposes nonzero boundary data that the lifting carries (docs/scene.md: `u`, and `gap`
        without normal unknowns)."""
        return any(b.u is not None or (b.gap is not None and not self.normal_unknowns) for b in self.boundaries)

    @property
    def lam(self):
        return lame(self.E, self.nu)[0]

    @property
    def mu(self):
        return lame(self.E, self.nu)[1]


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



def _read_doc(path):
    """The TOML text and document; unknown tables and keys are errors naming them."""
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
    return text, doc


def _read_mesh(path, doc, refine):
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
    return mesh


def _read_material(path, doc):
    mat = doc.get("material")
    if not isinstance(mat, dict):
        raise SceneError(f"{path}: missing [material]")
    E = _num(mat, "E", "material", positive=True)
    nu = _num(mat, "nu", "material")
    if not (-1.0 < nu < 0.5):
        raise SceneError(f"[material] nu = {nu} must lie in (-1, 0.5)")
    return E, nu


def _read_boundaries(doc):
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
        if kind not in ("dirichlet", "neumann", "contact", "symmetry"):
            raise SceneError(f"[{where}] ('{name}') kind must be dirichlet, neumann, contact or symmetry, "
                             f"got {kind!r}")
        _refuse_foreign_keys(where, name, kind, b)
        bd = Boundary(name, kind)
        if kind == "dirichlet" and "u" in b:
            u = VecExpr(b["u"], f"boundary '{name}' u")
            bd.u = None if u.is_zero else u
        if kind == "neumann":
            bd.traction = VecExpr(b.get("traction", ["0", "0"]), f"boundary '{name}' traction")
        if kind == "contact":
            _read_contact(where, name, b, bd)
        if kind == "symmetry":
            bd.kind, bd.g_a, bd.symmetry = "contact", Expr("0", f"boundary '{name}' (symmetry)"), True
        bnds.append(bd)
    if not any(b.kind in ("dirichlet", "contact") for b in bnds):
        # a_h (even with the jump term) is singular on rigid motions unless a Dirichlet part fixes them or contact
        # forces balance them (a floating body, tresca_py.floating)
        raise SceneError("[boundary] no dirichlet part: rigid motions are not fixed "
                         "(the paper requires meas(Gamma_D) > 0)")
    return bnds


_KEYS_OF = {"traction": ("neumann", "contact"), "g_a": ("contact",), "u": ("dirichlet",), "gap": ("contact",),
            "law": ("contact",), "coulomb": ("contact",)}


def _refuse_foreign_keys(where, name, kind, b):
    """A key that the part's kind does not take, refused naming the part."""
    for key, kinds in _KEYS_OF.items():
        if key in b and kind not in kinds:
            raise SceneError(f"[{where}] ('{name}') '{key}' is only allowed for kind = "
                             + " or ".join(f'"{k}"' for k in kinds))


def _read_contact(where, name, b, bd):
    """The keys of a contact part: law, g_a or coulomb (not both), gap, traction."""
    if "gap" in b:
        if not isinstance(b["gap"], str):
            raise SceneError(f"[{where}] ('{name}') 'gap' must be one expression string, got {b['gap']!r}")
        gap = Expr(b["gap"], f"boundary '{name}' gap")
        bd.gap = None if gap.is_zero else gap
    bd.law = b.get("law", "bilateral")
    if bd.law not in ("bilateral", "unilateral"):
        raise SceneError(f"[{where}] ('{name}') unknown contact law {bd.law!r} (expected \"bilateral\" or "
                         "\"unilateral\")")
    if "traction" in b:
        traction = VecExpr(b["traction"], f"boundary '{name}' traction")
        bd.traction = None if traction.is_zero else traction
    if "g_a" in b and "coulomb" in b:
        raise SceneError(f"[{where}] ('{name}') takes either 'g_a' (Tresca) or 'coulomb' (Coulomb), not both")
    if "g_a" not in b and "coulomb" not in b:
        raise SceneError(f"[{where}] ('{name}') contact needs 'g_a' (the friction bound) or 'coulomb'")
    key = "g_a" if "g_a" in b else "coulomb"
    bound = Expr(b[key], f"boundary '{name}' {key}")
    if bound.depends_on_t:
        raise SceneError(f"boundary '{name}' {key} must not depend on t")
    if key == "g_a":
        bd.g_a = bound
    else:
        bd.coulomb = bound


def _read_times(path, doc, steps):
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
    return times


def _read_exact(doc):
    """([exact] u, [exact] grad) as expressions, or (None, None)."""
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
    return exact_u, exact_grad


def load_scene(path, refine=None, steps=None):
    """Read and validate a scene TOML file. ``refine``/``steps`` override [mesh] refine / [time] steps."""
    text, doc = _read_doc(path)
    mesh = _read_mesh(path, doc, refine)
    E, nu = _read_material(path, doc)
    bnds = _read_boundaries(doc)
    loads = doc.get("loads", {})
    f = VecExpr(loads.get("f", ["0", "0"]), "[loads] f")
    u0 = VecExpr(doc.get("initial", {}).get("u0", ["0", "0"]), "[initial] u0")
    times = _read_times(path, doc, steps)
    rho = _num(doc.get("discretisation", {}), "rho", "discretisation", default=10.0)
    if rho <= 0:
        raise SceneError("[discretisation] rho must be positive (without the jump term CR elasticity is singular)")
    solver = {"method": "ssn", "tol": 1e-12, "max_iter": 500, "uzawa_step": 0.0}
    solver.update(doc.get("solver", {}))
    exact_u, exact_grad = _read_exact(doc)
    out = doc.get("output", {}).get("path")
    return Scene(path=str(path), text=text, title=str(doc.get("title", "")), mesh=mesh, E=float(E),
                 nu=float(nu), boundaries=bnds, f=f, u0=u0, times=times, rho=float(rho), solver=solver,
                 exact_u=exact_u, exact_grad=exact_grad, output=out)


def check_loads(scene, t, triangles_xy, neumann_xy):
    """Raise ``ExprError`` naming the load expression, a point and ``t`` where the loads of ``scene`` are not
    finite at a quadrature point of the load functional: ``[loads] f`` at the 6-point Dunavant points of the
    triangles ``triangles_xy`` (T, 3, 2), the traction of Neumann part ``name`` at the 3-point Gauss points of
    the edges ``neumann_xy[name]`` (k, 2, 2). A framework that assembles the loads itself (UFL) calls this to
    name the cause of a load vector that is not finite."""
    from tresca_py.quadrature import DUNAVANT_BARY, GAUSS3_S
    tri = np.asarray(triangles_xy, dtype=float).reshape(-1, 3, 2)
    if not scene.f.is_zero and len(tri):
        q = np.einsum("pk,tkd->tpd", DUNAVANT_BARY, tri)
        scene.f(q[..., 0], q[..., 1], t)
    for b in scene.boundaries:
        seg = np.asarray(neumann_xy.get(b.name, np.zeros((0, 2, 2))), dtype=float).reshape(-1, 2, 2)
        if b.kind == "neumann" and not b.traction.is_zero and len(seg):
            q = seg[:, None, 0] + GAUSS3_S[None, :, None] * (seg[:, None, 1] - seg[:, None, 0])
            b.traction(q[..., 0], q[..., 1], t)

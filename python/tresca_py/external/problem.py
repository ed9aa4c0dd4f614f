"""A scene TOML as a plain problem description for the external codes (own reader, no tresca-cr solver code).

The scene format is the project's (README "Scenes"): ``[mesh]`` corners/cells/diagonal/refine (a structured
triangulation of a quadrilateral, sides bottom/right/top/left, refined by red refinement), ``[material]``
E, nu, ``[[boundary]]`` parts (dirichlet with optional ``u``, neumann with ``traction``, contact with ``g_a``
and optional ``gap``), ``[loads] f``, ``[initial] u0``, ``[time] T, steps``, ``[exact] u, grad``.
Expressions are exmex strings in x, y, t; they are parsed with sympy and printed as numpy code, so that a
solver running under another interpreter (GetFEM under /usr/bin/python3) evaluates them with numpy alone
(:func:`evaluate`).  Gmsh scenes (``mesh.file``, Gmsh 4.1 relative to the scene file, 1D physical groups
naming the parts) are read with the project's mesh reader (``tresca_py.mesh``: meshio, red refinement), as
tresca-cr reads them: level ``refine`` is the file's mesh refined ``refine`` times.
"""
from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np

from tresca_py.elastic import lame
from tresca_py.expr import ExprError
from tresca_py.expr import parse as expr_parse


class ProblemError(ValueError):
    """A scene this reader cannot turn into a problem; the message names the key."""


def to_sympy(text, key):
    """exmex string -> sympy expression in x, y, t: the project's one reading (``tresca_py.expr``), so the
    external codes solve exactly the expressions tresca-cr reads (signum(0) = +1, the refused readings)."""
    try:
        return expr_parse(text, key)
    except ExprError as err:
        raise ProblemError(str(err)) from None


def numpy_code(expr):
    """sympy expression -> a numpy expression string in x, y, t (module name ``numpy``); Max/Min become nested
    numpy.maximum/minimum so that scalars and arrays broadcast."""
    from sympy.printing.numpy import NumPyPrinter

    class _Printer(NumPyPrinter):
        def _nest(self, fn, args):
            out = self._print(args[0])
            for a in args[1:]:
                out = f"numpy.{fn}({out}, {self._print(a)})"
            return out

        def _print_Max(self, e):
            return self._nest("maximum", e.args)

        def _print_Min(self, e):
            return self._nest("minimum", e.args)

    return _Printer({"fully_qualified_modules": True, "inline": True, "allow_unknown_functions": False}).doprint(expr)


def code(text, key):
    return numpy_code(to_sympy(text, key))


def evaluate(src, x, y, t):
    """Evaluate a :func:`code` string at points (x, y) and time t with numpy; broadcast to x's shape."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    with np.errstate(all="ignore"):
        val = eval(src, {"numpy": np, "x": x, "y": y, "t": float(t), "__builtins__": {}})  # noqa: S307
    return np.broadcast_to(np.asarray(val, dtype=float), x.shape).copy()


def structured_mesh(corners, n, m, diagonal="first"):
    """Points p(i,j) = bilinear map of (i/n, j/m), index j*(n+1)+i; cell (i,j) split along p(i,j)-p(i+1,j+1)
    ("first") or p(i+1,j)-p(i,j+1) ("second"); sides bottom (j=0), right (i=n), top (j=m), left (i=0),
    each a list of counter-clockwise vertex pairs."""
    c = np.asarray(corners, dtype=float)
    X, Y = np.meshgrid(np.arange(n + 1) / n, np.arange(m + 1) / m)
    X, Y = X.ravel()[:, None], Y.ravel()[:, None]
    pts = (1 - X) * (1 - Y) * c[0] + X * (1 - Y) * c[1] + X * Y * c[2] + (1 - X) * Y * c[3]

    def idx(i, j):
        return j * (n + 1) + i

    ii, jj = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(m)))
    p00, p10, p11, p01 = idx(ii, jj), idx(ii + 1, jj), idx(ii + 1, jj + 1), idx(ii, jj + 1)
    if diagonal == "first":
        tri = np.stack([np.stack([p00, p10, p11], 1), np.stack([p00, p11, p01], 1)], 1)
    else:
        tri = np.stack([np.stack([p00, p10, p01], 1), np.stack([p10, p11, p01], 1)], 1)
    i_n, j_m = np.arange(n), np.arange(m)
    sides = {"bottom": np.stack([idx(i_n, 0), idx(i_n + 1, 0)], 1),
             "right": np.stack([idx(n, j_m), idx(n, j_m + 1)], 1),
             "top": np.stack([idx(i_n + 1, m), idx(i_n, m)], 1),
             "left": np.stack([idx(0, j_m + 1), idx(0, j_m)], 1)}
    return pts, tri.reshape(-1, 3), sides


def file_mesh(path, refine):
    """Points, counter-clockwise triangles and {part: segments} of a Gmsh file refined ``refine`` times; each
    part's segments oriented counter-clockwise (as the triangle owning them) and chained from its start."""
    from tresca_py.mesh import gmsh_mesh, red_refine
    from tresca_py.scene import SceneError
    if refine < 0:
        raise ProblemError(f"{path}: refine {refine}: a Gmsh mesh cannot be coarsened")
    try:
        mesh = gmsh_mesh(path)
    except SceneError as err:
        raise ProblemError(str(err)) from None
    for _ in range(refine):
        mesh = red_refine(mesh)
    tri = mesh.triangles
    ccw = {(int(a), int(b)) for t in tri for a, b in ((t[0], t[1]), (t[1], t[2]), (t[2], t[0]))}
    sides = {}
    for name, seg in mesh.boundary_segments.items():
        seg = np.array([(a, b) if (a, b) in ccw else (b, a) for a, b in seg.tolist()], dtype=np.int64)
        nxt = {a: k for k, (a, _) in enumerate(seg.tolist())}
        heads = set(seg[:, 0].tolist()) - set(seg[:, 1].tolist())
        k, order = nxt[min(heads)] if heads else 0, []
        while k is not None and len(order) < len(seg):
            order.append(k)
            k = nxt.get(int(seg[k, 1]))
        if len(order) != len(seg):   # several chains (a part in pieces): keep them, unchained
            order += [i for i in range(len(seg)) if i not in set(order)]
        sides[name] = seg[order]
    return mesh.points, tri, sides


def _num(tab, key, where, default=None):
    val = tab.get(key, default)
    if not isinstance(val, (int, float)) or isinstance(val, bool) or not math.isfinite(val):
        raise ProblemError(f"{where}.{key}: expected a number, got {val!r}")
    return float(val)


def _vec(texts, key):
    if texts is None:
        return None
    if not isinstance(texts, list) or len(texts) != 2:
        raise ProblemError(f"{key}: expected two expression strings, got {texts!r}")
    return [code(s, f"{key}[{i}]") for i, s in enumerate(texts)]


def _contact_law(b, k):
    """A contact part's law (bilateral or unilateral u·n ≤ g), its Coulomb coefficient F (code or None: Tresca
    with g_a) and its prescribed contact traction t_C (σ(u)n = r + t_C on Γ_C, r the reaction; or None)."""
    law = b.get("law", "bilateral")
    if law not in ("bilateral", "unilateral"):
        raise ProblemError(f"boundary[{k}].law: {law!r} is not bilateral/unilateral")
    coulomb = b.get("coulomb")
    return {"law": law, "coulomb": None if coulomb is None else code(coulomb, f"boundary[{k}].coulomb"),
            "contact_traction": _vec(b.get("traction"), f"boundary[{k}].traction")}


def read_scene(path):
    """The TOML of a scene as a dict (tomllib), with a clear error for a missing or malformed file."""
    path = Path(path)
    try:
        return tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as err:
        raise ProblemError(f"{path}: {err}") from None


def load(path):
    """Parse scene ``path`` once (expressions to numpy code): the level-independent part of a problem."""
    sc = read_scene(path)
    mesh = dict(sc.get("mesh", {}))
    if "file" in mesh:
        mesh["file"] = str(Path(path).parent / mesh["file"])
        sides = file_mesh(mesh["file"], 0)[2]
    elif "corners" not in mesh or "cells" not in mesh:
        raise ProblemError(f"{path}: mesh.corners and mesh.cells (or mesh.file) are required")
    else:
        sides = ("bottom", "right", "top", "left")
    mat = sc.get("material", {})
    E, nu = _num(mat, "E", "material"), _num(mat, "nu", "material")
    parts, n_contact = [], 0
    for k, b in enumerate(sc.get("boundary", [])):
        name, kind = b.get("name"), b.get("kind")
        if name not in sides:
            raise ProblemError(f"boundary[{k}].name: unknown part {name!r} ({', '.join(sides)})")
        part = {"name": name, "kind": kind}
        if kind == "dirichlet":
            part["u"] = _vec(b.get("u", ["0", "0"]), f"boundary[{k}].u")
        elif kind == "neumann":
            part["traction"] = _vec(b.get("traction", ["0", "0"]), f"boundary[{k}].traction")
        elif kind == "contact":
            n_contact += 1
            part["g_a"] = code(b.get("g_a", "0"), f"boundary[{k}].g_a")
            part["gap"] = code(b.get("gap", "0"), f"boundary[{k}].gap")
            part.update(_contact_law(b, k))
        elif kind != "symmetry":  # symmetry: u·n = 0 with zero tangential traction (a roller)
            raise ProblemError(f"boundary[{k}].kind: {kind!r} is not dirichlet/neumann/contact/symmetry")
        parts.append(part)
    if n_contact != 1:
        raise ProblemError(f"{path}: exactly one contact part is supported, found {n_contact}")
    tm, ex = sc.get("time", {}), sc.get("exact")
    exact = None if ex is None else {"u": _vec(ex["u"], "exact.u"),
                                     "grad": [_vec(ex["grad"][i], f"exact.grad[{i}]") for i in range(2)]}
    return {"title": sc.get("title", Path(path).stem), "scene": str(path), "mesh": mesh, "parts": parts,
            "E": E, "nu": nu, "lam": lame(E, nu)[0], "mu": lame(E, nu)[1],
            "f": _vec(sc.get("loads", {}).get("f"), "loads.f"),
            "u0": _vec(sc.get("initial", {}).get("u0"), "initial.u0"),
            "T": _num(tm, "T", "time"), "steps": int(tm.get("steps", 1)), "exact": exact}


def at_level(scene, refine, steps=None, degree=2, gamma_n=10.0):
    """The problem of a :func:`load`-ed scene on mesh level ``refine`` (cells × 2^refine, refine may be negative
    where the cells halve evenly) with ``steps`` uniform
    steps (default: the scene's), as a JSON-serialisable dict for the external solvers. γ_N: the Nitsche
    parameter, p = γ_N (λ + 2μ)/h (λ + 2μ, not E: the trace inequality for σ(v)n carries λ, and with E the
    symmetric Nitsche term lost coercivity on the λ/μ = 10⁴ case: a spurious level in both P2 codes)."""
    mesh = scene["mesh"]
    if "file" in mesh:
        pts, tri, sides = file_mesh(mesh["file"], refine)
    else:
        n, m = (c * 2.0 ** refine for c in mesh["cells"])  # refine < 0 coarsens cells that halve evenly
        if n != int(n) or m != int(m) or n < 1 or m < 1:
            raise ProblemError(f"{scene['scene']}: refine {refine} does not give whole cells from {mesh['cells']}")
        pts, tri, sides = structured_mesh(mesh["corners"], int(n), int(m), mesh.get("diagonal", "first"))
    parts = [dict(p, segments=sides[p["name"]].tolist()) for p in scene["parts"]]
    contact = next(p for p in parts if p["kind"] == "contact")
    n_steps = int(steps or scene["steps"])
    prob = {k: v for k, v in scene.items() if k not in ("mesh", "parts", "T", "steps")}
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    h = float(np.max(np.linalg.norm(pts[edges[:, 0]] - pts[edges[:, 1]], axis=1)))
    prob.update({"refine": refine, "degree": degree, "points": pts.tolist(), "triangles": tri.tolist(),
                 "parts": parts, "times": (np.arange(n_steps + 1) * scene["T"] / n_steps).tolist(),
                 "gamma_n": gamma_n, "h": h, "probes": contact_probes(pts, sides[contact["name"]])})
    # whether Γ_C's start / end vertex lies on a Dirichlet part (quantities.summarise: the slip vanishes there)
    dir_vertices = {int(v) for p in parts if p["kind"] == "dirichlet" for seg in p["segments"] for v in seg}
    segs = sides[contact["name"]]
    prob["probes"]["dirichlet_ends"] = [int(segs[0][0]) in dir_vertices, int(segs[-1][1]) in dir_vertices]
    return prob


def build(path, refine, steps=None, degree=2, gamma_n=10.0):
    """:func:`at_level` of :func:`load` (one level; parse once with ``load`` for several)."""
    return at_level(load(path), refine, steps, degree, gamma_n)


def contact_probes(pts, segs, n_samples=513):
    """Γ_C's parametrisation (start point, unit tangent τ = (−n_y, n_x) with n the outward normal, length),
    the three probe points at 1/4, 1/2, 3/4 of its length and ``n_samples`` uniform sample points, for a
    straight contact side; ``curved`` says that Γ_C's vertices leave its chord (a polygon such as Hertz's arc):
    then the solvers take each edge's own normal and the probes along the chord mean nothing (u·τ there: NaN)."""
    a, b = pts[segs[0][0]], pts[segs[-1][1]]
    length = float(np.hypot(*(b - a)))
    verts = pts[np.asarray(segs).ravel()] - a
    chord = (b - a) / length
    curved = bool(np.max(np.abs(verts[:, 0] * chord[1] - verts[:, 1] * chord[0])) > 1e-10 * length)
    tau = (b - a) / length  # counter-clockwise boundary direction = (−n_y, n_x) for the outward normal n
    s = np.linspace(0.0, length, n_samples)
    normal = np.array([tau[1], -tau[0]])
    inward = -1e-10 * length * normal  # keeps probes inside the mesh against rounding on a rotated side
    return {"start": a.tolist(), "tangent": tau.tolist(), "normal": normal.tolist(), "curved": curved,
            "length": length, "points": [(a + f * (b - a) + inward).tolist() for f in (0.25, 0.5, 0.75)],
            "samples": (a[None, :] + s[:, None] * tau[None, :] + inward[None, :]).tolist()}

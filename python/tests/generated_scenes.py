"""Manufactured scenes generated for the tests with tresca_py.mms (f = -div sigma(u), g = sigma(u) n):
affine patch tests (both diagonals; with frictionless contact) and a smooth plane-elasticity solution."""
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.mms.derive import derive
from tresca_py.mms.scene_toml import scene_text

x, y, t = symbols()
R = sp.Rational


def case(name, u, corners, cells, kinds, diagonal="first", g_a=None, steps=2):
    return dict(name=name, title=name, header=f"test scene {name} (python/tests/generated_scenes.py)",
                E=R(100), nu=R(3, 10), corners=corners, cells=cells, diagonal=diagonal, kinds=kinds, u=u,
                g_a=g_a, T=1, steps=steps)


def generated_scenes():
    """name -> scene text."""
    out = {}
    # affine field vanishing on the (skewed) right side c1-c2
    corners = [[0, 0], [3, R(1, 2)], [R(7, 2), R(5, 2)], [R(1, 2), 2]]
    ell = R(1, 2) * (y - R(1, 2)) - 2 * (x - 3)
    s = R(1, 2) + t
    u = [s * ell / 1000, -s * ell * 2 / 1000]
    kinds = {"bottom": "neumann", "right": "dirichlet", "top": "neumann", "left": "neumann"}
    for diag in ("first", "second"):
        out[f"patch_elastic_{diag}"] = scene_text(derive(case(f"patch_elastic_{diag}", u, corners, [5, 4], kinds,
                                                              diagonal=diag)))
    # frictionless contact patch test: u = s(t) (x - 3, 0)/1000 on a block with a vertical right side
    corners_c = [[0, 0], [3, 0], [3, R(5, 2)], [R(2, 5), 2]]
    kinds_c = {"bottom": "contact", "right": "dirichlet", "top": "neumann", "left": "neumann"}
    out["patch_contact"] = scene_text(derive(case("patch_contact", [s * (x - 3) / 1000, sp.Integer(0)], corners_c,
                                                  [6, 5], kinds_c, g_a=sp.Integer(0), steps=3)))
    # smooth manufactured plane elasticity on the unit square (left side clamped)
    u_m = [(1 + t) / 10 * sp.sin(x) * sp.exp(y / 2), (1 + t) / 10 * x ** 2 * sp.cos(y)]
    kinds_m = {"bottom": "neumann", "right": "neumann", "top": "neumann", "left": "dirichlet"}
    out["mms_elastic"] = scene_text(derive(case("mms_elastic", u_m, [[0, 0], [1, 0], [1, 1], [0, 1]], [4, 4],
                                                kinds_m)))
    return out

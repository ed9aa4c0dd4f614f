"""Generate the manufactured plain-elasticity scenes used by tests/library/elasticity.rs.

Exact solutions vanish on the clamped side; f = -div sigma(u) and the tractions sigma(u) n on the other
sides are derived with sympy (tresca_py.mms) and printed in the solver's expression syntax (exmex: ^ for
powers, no unary minus before a power). Run from the repository root:
    .venv/bin/python verification/cases/gen_elastic.py
"""
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.mms.elastic_scene import scene_text

x, y, _ = symbols()

# rectangle (0,2) x (0,1), clamped at x = 0
u = [sp.sin(x) * sp.cos(y) / 10, x * sp.exp(y / 2) * sp.cos(x) / 10]
rect = scene_text("manufactured elasticity on a rectangle", "[[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]", u,
                  {"bottom": (0, -1), "right": (1, 0), "top": (0, 1), "left": (-1, 0)}, "left")
open("verification/cases/elastic_rect.toml", "w").write(rect)

# unit square rotated by 30 degrees about the origin, clamped on the side c3 -> c0
c, s = sp.cos(sp.pi / 6), sp.sin(sp.pi / 6)
cf, sf = float(c), float(s)
corners = f"[[0.0, 0.0], [{cf!r}, {sf!r}], [{cf - sf!r}, {sf + cf!r}], [{-sf!r}, {cf!r}]]"
d = c * x + s * y  # distance from the clamped side
u = [d * sp.cos(x + y) / 10, d * sp.sin(x - 2 * y) / 10]
rot = scene_text("manufactured elasticity on a rotated square", corners, u,
                 {"bottom": (s, -c), "right": (c, s), "top": (-s, c), "left": (-c, -s)}, "left")
open("verification/cases/elastic_rotated.toml", "w").write(rot)
print("wrote verification/cases/elastic_rect.toml, verification/cases/elastic_rotated.toml")

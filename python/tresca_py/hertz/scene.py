"""The scene text of the Hertz case: the quarter disc of :mod:`tresca_py.hertz.mesh` (radius R, centre (0, R)) on
the rigid plane y = 0, frictionless unilateral contact on the lower arc, a symmetry part on the axis x = 0, a free
outer arc, and the cut y = R through the centre pushed down by δ (Dirichlet u = (0, −δ t)). The force per unit
length P is not imposed but measured (Σ_e |e| p_e n_y over Γ_C, twice for the full cylinder), so the check against
Hertz's formulas holds for whatever P results.

The gap of a point (x, y) of the arc to the plane, measured along the circle's outward normal
n = (x, y − R)/R, is y R/(R − y) (the linearised, normal-gap Signorini condition u·n ≤ gap): the polygon's own
gap, since its vertices lie on the circle and its edges inside it by at most the sagitta h²/(8R).
``circle_gap`` gives every point the circle's gap at its angle instead, R ρ/(R − y) − R with
ρ = |(x, y − R)| (the same on the circle): the polygon's error in the gap removed, for measuring it.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Case:
    """Material and load of one Hertz scene (R the radius, delta the imposed approach of the centre line)."""
    R: float
    E: float
    nu: float
    delta: float
    circle_gap: bool = False


def scene_text(case: Case, mesh_file, title):
    """The TOML text of the scene on ``mesh_file`` (a path relative to the scene file)."""
    R = repr(float(case.R))
    gap = f"{R}*sqrt(x^2+({R}-y)^2)/({R}-y)-{R}" if case.circle_gap else f"y*{R}/({R}-y)"
    return f"""title = "{title}"

[mesh]
file   = "{mesh_file}"
refine = 0

[material]
E  = {case.E!r}
nu = {case.nu!r}

[[boundary]]
name = "axis"
kind = "symmetry"

[[boundary]]
name = "top"
kind = "dirichlet"
u = ["0", "-{case.delta!r}*t"]

[[boundary]]
name = "free"
kind = "neumann"

[[boundary]]
name = "contact"
kind = "contact"
law = "unilateral"
g_a = "0"
gap = "{gap}"

[time]
T = 1.0
steps = 1

[solver]
method   = "ssn"
tol      = 1e-12
max_iter = 200
"""

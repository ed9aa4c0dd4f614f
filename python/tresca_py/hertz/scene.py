"""The scene text of the Hertz case: the quarter disc of :mod:`tresca_py.hertz.mesh` (radius R, centre (0, R)) on
the rigid plane y = 0, frictionless unilateral contact on the lower arc, a symmetry part on the axis x = 0, a free
outer arc, and the cut y = R through the centre loaded one of two ways:

* ``P`` given (the issue's set-up): a traction (0, −P/(2R)) on the cut, so the half cylinder x ∈ [−R, R] carries
  the force per unit length P; no Dirichlet part: the body floats, held in y by the contact alone;
* ``delta`` given: the cut pushed down by δ (Dirichlet u = (0, −δ t)).

Either way the check against Hertz uses the P measured on Γ_C (Σ_e |e| p_e |n_y|, twice for the full cylinder),
which in the floating form equals the given P to the solver's tolerance (the body's vertical equilibrium).

The gap of a point (x, y) of the arc to the plane, measured along the circle's outward normal
n = (x, y − R)/R, is y R/(R − y) (the linearised, normal-gap Signorini condition u·n ≤ gap): the polygon's own
gap, since its vertices lie on the circle and its edges inside it by at most the sagitta h²/(8R).
``circle_gap`` gives every point the circle's gap at its angle instead, R ρ/(R − y) − R with
ρ = |(x, y − R)| (the same on the circle): the polygon's error in the gap removed, for measuring it.
"""
from dataclasses import dataclass


@dataclass(frozen=True)
class Case:
    """Material and load of one Hertz scene: R the radius, and either P (the force per unit length, floating) or
    delta (the imposed approach of the centre line)."""
    R: float
    E: float
    nu: float
    delta: float | None = None
    P: float | None = None
    circle_gap: bool = False

    def __post_init__(self):
        if (self.delta is None) == (self.P is None):
            raise ValueError(f"a Hertz case gives exactly one of delta and P, got delta = {self.delta}, P = {self.P}")


def scene_text(case: Case, mesh_file, title):
    """The TOML text of the scene on ``mesh_file`` (a path relative to the scene file)."""
    R = repr(float(case.R))
    top = (f'kind = "neumann"\ntraction = ["0", "-{case.P / (2 * case.R)!r}*t"]' if case.P is not None
           else f'kind = "dirichlet"\nu = ["0", "-{case.delta!r}*t"]')
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
{top}

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

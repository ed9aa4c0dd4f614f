"""Hertz's line contact of an elastic cylinder (radius R) on a rigid plane, plane strain, frictionless
(Johnson, *Contact Mechanics*, 1985, §4.3, two-dimensional contact of cylinders): with E* = E/(1 − ν²) and P
the force per unit length,

    a  = √(4 P R / (π E*))        contact half-width
    p₀ = 2 P / (π a)              peak pressure,  p(x) = p₀ √(1 − x²/a²) on |x| < a,  ∫ p dx = P.

The solution is that of an elastic half-space under the parabolic gap x²/(2R); a cylinder of finite radius
departs from it by relative O((a/R)²) (the next term of the circle, x⁴/(8R³), over the contact zone is (a/R)²/4
of the parabolic gap; the finite body changes the surface slope by O(P/(E* R)) = O((a/R)²)), up to a factor
log(R/a) from the 2D far field. A scheme that imposes the contact along the body's own normal instead of the
vertical adds a first-order term (tresca_py.verify.hertz).
"""
import math

import numpy as np


def e_star(E, nu):
    """Plane-strain modulus E* = E/(1 − ν²) of an elastic body on a rigid plane."""
    return E / (1.0 - nu * nu)


def half_width(P, R, E, nu):
    """Contact half-width a = √(4PR/(πE*)) for the force per unit length P > 0."""
    if P <= 0 or R <= 0:
        raise ValueError(f"Hertz half-width needs P > 0 and R > 0, got P = {P}, R = {R}")
    return math.sqrt(4.0 * P * R / (math.pi * e_star(E, nu)))


def peak_pressure(P, a):
    """Peak pressure p₀ = 2P/(πa)."""
    return 2.0 * P / (math.pi * a)


def load_for(a_over_R, R, E, nu):
    """The force per unit length P whose half-width is a = a_over_R · R: P = π E* a² / (4R)."""
    a = a_over_R * R
    return math.pi * e_star(E, nu) * a * a / (4.0 * R)


def profile(x, a, p0):
    """Hertz pressure p₀ √(1 − x²/a²) inside |x| < a, 0 outside."""
    x = np.asarray(x, dtype=float)
    return p0 * np.sqrt(np.clip(1.0 - (x / a) ** 2, 0.0, None))


def edge_means(x0, x1, a, p0):
    """Mean of the Hertz profile over each segment [x0, x1] of the x axis, exactly: with x = a sin t,
    ∫ √(1 − x²/a²) dx = (a/2)(t + sin t cos t), t clipped to [−π/2, π/2] outside the zone."""
    x0, x1 = np.asarray(x0, float), np.asarray(x1, float)

    def primitive(x):
        t = np.arcsin(np.clip(x / a, -1.0, 1.0))
        return 0.5 * a * (t + np.sin(t) * np.cos(t))

    length = x1 - x0
    return p0 * np.where(length != 0, (primitive(x1) - primitive(x0)) / np.where(length != 0, length, 1.0),
                         profile(x0, a, 1.0))

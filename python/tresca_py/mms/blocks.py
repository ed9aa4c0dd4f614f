"""Piecewise building blocks of the manufactured solutions, with exact derivative rules (so sympy
differentiates them exactly), their numpy forms, and ``lam``: a sympy expression as a numpy function.

PosPow(z, n) = max(0, z)^n; SStep(z, d) = d-th derivative of S(min(max(z, 0), 1)), S(c) = 10c^3 - 15c^4 + 6c^5
(C^2); Step = Heaviside with Step(0) = 1/2 (only in time derivatives used by the checks, never printed).
"""
import numpy as np
import sympy as sp

from tresca_py.expr import symbols

x, y, t = symbols()

class Step(sp.Function):
    """Heaviside step with Step(0) = 1/2. Only ever appears in time derivatives (checks), never printed."""

    @classmethod
    def eval(cls, z):
        if z.is_Rational:
            return sp.S.One if z > 0 else (sp.S.Zero if z < 0 else sp.S.Half)


class PosPow(sp.Function):
    """PosPow(z, n) = max(0, z)^n for integer n >= 1."""

    @classmethod
    def eval(cls, z, n):
        if z.is_Rational:
            return sp.Max(0, z) ** n

    def fdiff(self, argindex=1):
        z, n = self.args
        if argindex != 1:
            raise sp.ArgumentIndexError(self, argindex)
        return n * PosPow(z, n - 1) if n >= 2 else Step(z)


class SStep(sp.Function):
    """SStep(z, d) = d-th derivative of S(clamp(z)), S(c) = 10c^3 - 15c^4 + 6c^5 (C^2 smoothstep).
    Printed with clamp(z) = max(z,0) - max(z-1,0) (no nested max/min).

    S'(c) = 30c^2(1-c)^2 and S''(c) = 60c(1-c)(1-2c) vanish at c = 0 and c = 1, so the clamp
    needs no indicator for d <= 2. d = 3 has jumps at z = 0, 1 (numerical use only)."""

    @classmethod
    def eval(cls, z, d):
        if z.is_Rational and d <= 2:
            c = sp.Min(sp.Max(z, 0), 1)
            return [c**3 * (10 - 15*c + 6*c**2), 30*c**2*(1 - c)**2, 60*c*(1 - c)*(1 - 2*c)][int(d)]

    def fdiff(self, argindex=1):
        z, d = self.args
        if argindex != 1:
            raise sp.ArgumentIndexError(self, argindex)
        if d >= 3:
            raise ValueError("SStep derivative of order > 3 not supported")
        return SStep(z, d + 1)


def _np_pospow(z, n):
    z = np.asarray(z, dtype=float)
    return np.maximum(0.0, z) ** int(n)


def _np_sstep(z, d):
    z = np.asarray(z, dtype=float)
    c = np.clip(z, 0.0, 1.0)
    d = int(d)
    if d == 0:
        return c ** 3 * (10 - 15 * c + 6 * c ** 2)
    if d == 1:
        return 30 * c ** 2 * (1 - c) ** 2
    if d == 2:
        return 60 * c * (1 - c) * (1 - 2 * c)
    return np.where((z > 0) & (z < 1), 60 - 360 * c + 360 * c ** 2, 0.0)


NP_MODULES = [{"PosPow": _np_pospow, "SStep": _np_sstep,
               "Step": lambda z: np.heaviside(np.asarray(z, dtype=float), 0.5)}, "numpy"]


def lam(expr):
    """Numerical function (x, y, t) -> array of a sympy expression (broadcasting)."""
    expr = sp.sympify(expr)
    f = sp.lambdify((x, y, t), expr, modules=NP_MODULES)
    return lambda X, Y, T: np.broadcast_to(np.asarray(f(X, Y, T), dtype=float),
                                           np.broadcast(X, Y, T).shape).copy()

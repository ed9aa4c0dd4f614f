#!/usr/bin/env python3
"""Manufactured Tresca problems with exact solutions for tresca-cr.

Run from the repository root:

    .venv/bin/python verification/mms/derive.py            # derive, check, write verification/cases/*.toml
    .venv/bin/python verification/mms/derive.py --check    # derive and check only, write nothing
    .venv/bin/python verification/mms/derive.py --no-selftest   # skip the mutant self-test (halves the time)
    .venv/bin/python verification/mms/derive.py --exmex BIN   # also evaluate every emitted string with a
                                                              # real exmex binary (see README.md)

For every case an exact displacement u(x, y, t) is chosen; sympy then derives

    f   = -div sigma(u)                  body force,
    g   = sigma(u) n                     traction on every Neumann side,
    g_a (time independent)               friction bound on Gamma_C,
    u0  = u(., 0)                        initial value,
    grad u                               for the solver's true-error computation,

prints all of them in the syntax of the Rust `exmex` crate, parses the printed strings back
into sympy and compares them numerically with the originals, and then CHECKS the strong form of
the problem pointwise on fine grids in space and time (equilibrium, u = 0 on Gamma_D, u.n = 0 on
Gamma_C, |sigma_t| <= g_a, stick where |sigma_t| < g_a, u_t' = -theta sigma_t with theta >= 0
where slipping, compatibility of u0). Any failed check aborts with a non-zero exit status and no
file is written.

Conventions (those of docs/model.md of the repository): n outward unit normal, tau = (-n_y, n_x),
sigma_t = sigma(u) n - (sigma(u) n . n) n; the solver reports sigma_t . tau and the slip u . tau.

Piecewise building blocks (all C^2 in their argument, so u(., t) is in H^2 and even W^{3,inf}):
  PosPow(z, n) = max(0, z)^n                 (n = 3 in the solutions; derivatives n PosPow(z, n-1))
  SStep(z, d)  = d-th derivative of S(min(max(z, 0), 1)),  S(c) = 10c^3 - 15c^4 + 6c^5
They are sympy Functions with explicit derivative rules, so sympy differentiates them exactly, and
the printer writes them with max/min. Derivatives that are discontinuous (Heaviside-like) are never
printed; they only occur in the time derivatives used by the checks.

Everything is exact rational arithmetic until the numerical checks, so the output is deterministic.
"""

import argparse
import pathlib
import subprocess
import sys

import numpy as np
import sympy as sp
from sympy.parsing.sympy_parser import parse_expr

x, y, t = sp.symbols("x y t", real=True)
R = sp.Rational
HERE = pathlib.Path(__file__).resolve().parent
CASES_DIR = HERE.parent / "cases"


class CheckFailed(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# 1. Piecewise building blocks with exact derivative rules
# ---------------------------------------------------------------------------------------------

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


# ---------------------------------------------------------------------------------------------
# 2. Printer to exmex syntax, and the inverse parser for the round-trip test
# ---------------------------------------------------------------------------------------------
# exmex quirks (checked against exmex 0.21): unary minus binds tighter than ^ ("-2^2" = 4, "2*-x^2"
# = 2*(-x)^2), so the printer never emits a unary minus: negative numbers are "(0-p)", negative
# terms are subtracted, negative products are "((0-1)*(...))". Everything non-atomic is wrapped in
# parentheses. No floats are emitted (all coefficients are exact rationals "(p/q)").

class NotPrintable(Exception):
    pass


_FUNCS = {sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.exp: "exp", sp.tanh: "tanh",
          sp.sinh: "sinh", sp.cosh: "cosh", sp.log: "ln", sp.Abs: "abs", sp.sign: "signum"}


def minmax(name, args):
    """name(a1, a2, ...) for name in (min, max) WITHOUT nesting two-argument functions.

    exmex 0.21 rejects a two-argument function inside the second argument of another one
    ("min(1,max(0,t))": 'parentheses mismatch'), and the solver's scene lint (src/scene/expr/lint.rs) rejects
    any nesting of min/max/atan2. So name(a, b) is only written when neither argument contains
    one; otherwise max(a, b) = (a + b + abs(a - b))/2 and min(a, b) = (a + b - abs(a - b))/2."""
    s = args[0]
    for a in args[1:]:
        if "," in a or "," in s:
            sgn = "+" if name == "max" else "-"
            s = "((%s+%s%sabs(%s-%s))/2)" % (s, a, sgn, s, a)
        else:
            s = name + "(" + s + "," + a + ")"
    return s


def exmex_lint(s):
    """Reject what exmex 0.21 mis-parses or the solver's lint refuses: '**', unary minus, min/max/atan2
    nested inside min/max/atan2, unbalanced parentheses. Returns a list of problems (empty = fine)."""
    bad = []
    if "**" in s:
        bad.append("'**'")
    for i, ch in enumerate(s):
        if ch == "-" and (i == 0 or not (s[i - 1].isalnum() or s[i - 1] in "_)")):
            bad.append("unary minus at %d" % i)
    depth, stack = 0, []                      # stack of (depth, seen_comma) for 2-arg functions
    i = 0
    while i < len(s):
        ch = s[i]
        if ch == "(":
            depth += 1
            is2 = any(s[max(0, i - len(f)):i] == f and (i - len(f) == 0 or not s[i - len(f) - 1].isalnum())
                      for f in ("min", "max", "atan2"))
            stack.append([depth, False, is2])
        elif ch == ")":
            if not stack:
                bad.append("unbalanced ')' at %d" % i)
                break
            stack.pop()
            depth -= 1
        elif ch == ",":
            if not stack or not stack[-1][2] or stack[-1][1]:
                bad.append("stray comma at %d" % i)
            else:
                stack[-1][1] = True
                # any enclosing 2-arg function already past its comma -> we are in a second argument
            if any(fr[2] for fr in stack[:-1]):
                bad.append("min/max/atan2 nested inside min/max/atan2 at %d" % i)
        i += 1
    if stack:
        bad.append("unbalanced '('")
    return bad


def ex(e):
    """sympy expression -> exmex string."""
    e = sp.sympify(e)
    if e.is_Integer:
        return str(int(e)) if e >= 0 else "(0-%d)" % (-int(e))
    if e.is_Rational:
        p, q = int(e.p), int(e.q)
        return "(%d/%d)" % (p, q) if p >= 0 else "(0-(%d/%d))" % (-p, q)
    if e.is_Float:
        raise NotPrintable("float literal %r: use exact rationals" % e)
    if e is sp.pi:
        return "PI"
    if e is sp.E:
        return "exp(1)"
    if e.is_Symbol:
        return e.name
    if e.is_Add:
        terms = e.as_ordered_terms()
        pos = [a for a in terms if not a.could_extract_minus_sign()]
        neg = [a for a in terms if a.could_extract_minus_sign()]
        s = ex(pos[0]) if pos else "0"
        for a in pos[1:]:
            s += "+" + ex(a)
        for a in neg:
            s += "-" + ex(-a)
        return "(" + s + ")"
    if e.is_Mul:
        if e.could_extract_minus_sign():
            return "((0-1)*" + ex(-e) + ")"
        num, den = [], []
        for a in e.as_ordered_factors():
            if a.is_Pow and a.exp.is_Rational and a.exp < 0:
                den.append(a.base ** (-a.exp))
            elif a.is_Rational and a.q != 1:
                if a.p != 1:
                    num.append(sp.Integer(a.p))
                den.append(sp.Integer(a.q))
            else:
                num.append(a)
        s = "*".join(ex(a) for a in num) if num else "1"
        if den:
            s = "(" + s + ")/(" + "*".join(ex(a) for a in den) + ")"
        return "(" + s + ")"
    if e.is_Pow:
        b, p = e.base, e.exp
        if p == R(1, 2):
            return "sqrt(" + ex(b) + ")"
        if p.is_Rational and p < 0:
            return "(1/" + ex(b ** (-p)) + ")"
        return "(" + ex(b) + "^" + ex(p) + ")"
    if isinstance(e, (sp.Max, sp.Min)):
        return minmax("max" if isinstance(e, sp.Max) else "min", [ex(a) for a in e.args])
    if isinstance(e, PosPow):
        z, n = e.args
        if n == 1:
            return "max(" + ex(z) + ",0)"
        return "(max(" + ex(z) + ",0)^" + str(int(n)) + ")"
    if isinstance(e, SStep):
        z, d = e.args
        c = "(max(" + ex(z) + ",0)-max(" + ex(z - 1) + ",0))"     # = min(max(z,0),1), no nesting
        if d == 0:
            return "((%s^3)*(10-(15*%s)+(6*(%s^2))))" % (c, c, c)
        if d == 1:
            return "(30*(%s^2)*((1-%s)^2))" % (c, c)
        if d == 2:
            return "(60*%s*(1-%s)*(1-(2*%s)))" % (c, c, c)
        raise NotPrintable("SStep derivative of order %s is discontinuous" % d)
    if isinstance(e, Step):
        raise NotPrintable("Step (discontinuous) must not appear in printed data")
    if e.func in _FUNCS:
        return _FUNCS[e.func] + "(" + ex(e.args[0]) + ")"
    raise NotPrintable("no exmex form for %s" % e.func)


_PARSE_NS = {"x": x, "y": y, "t": t, "max": sp.Max, "min": sp.Min, "abs": sp.Abs, "signum": sp.sign,
             "ln": sp.log, "sqrt": sp.sqrt, "exp": sp.exp, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan,
             "tanh": sp.tanh, "sinh": sp.sinh, "cosh": sp.cosh, "PI": sp.pi, "E": sp.E}


def parse_exmex(s):
    """exmex string -> sympy expression (with sympy Max/Min, i.e. independent of the custom classes)."""
    if "**" in s:
        raise CheckFailed("'**' in emitted expression")
    return parse_expr(s.replace("^", "**"), local_dict=dict(_PARSE_NS), global_dict={"Integer": sp.Integer,
                      "Rational": sp.Rational, "Float": sp.Float, "Symbol": sp.Symbol}, evaluate=True)


# ---------------------------------------------------------------------------------------------
# 3. Elasticity
# ---------------------------------------------------------------------------------------------

def lame(E, nu):
    """Plane-strain Lame constants (lambda, mu)."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def grad_of(u):
    """[[du1/dx, du1/dy], [du2/dx, du2/dy]]."""
    return sp.Matrix([[sp.diff(u[0], x), sp.diff(u[0], y)], [sp.diff(u[1], x), sp.diff(u[1], y)]])


def stress(G, lam_, mu):
    eps = (G + G.T) / 2
    return lam_ * eps.trace() * sp.eye(2) + 2 * mu * eps


def body_force(S):
    """f = -div sigma (row divergence)."""
    return [-(sp.diff(S[0, 0], x) + sp.diff(S[0, 1], y)), -(sp.diff(S[1, 0], x) + sp.diff(S[1, 1], y))]


# ---------------------------------------------------------------------------------------------
# 4. Geometry of the structured quadrilateral (corners c0 c1 c2 c3 counter-clockwise)
# ---------------------------------------------------------------------------------------------

SIDES = {"bottom": (0, 1), "right": (1, 2), "top": (2, 3), "left": (3, 0)}


def side_geometry(corners, side):
    """Start point, end point, outward unit normal, tangent tau = (-n_y, n_x) (numpy)."""
    i, j = SIDES[side]
    a = np.array([float(v) for v in corners[i]])
    b = np.array([float(v) for v in corners[j]])
    d = (b - a) / np.linalg.norm(b - a)
    n = np.array([d[1], -d[0]])
    return a, b, n, np.array([-n[1], n[0]])


def side_normal_exact(corners, side):
    i, j = SIDES[side]
    d = sp.Matrix(corners[j]) - sp.Matrix(corners[i])
    d = d / sp.sqrt(d.dot(d))
    return sp.Matrix([d[1], -d[0]]).applyfunc(sp.nsimplify)


# ---------------------------------------------------------------------------------------------
# 5. The cases
# ---------------------------------------------------------------------------------------------
# Common construction on a contact side that is the local X axis (local coordinates X along the
# side, Y into the body, local outward normal (0,-1), tau = (1,0)): with U2(X,0) = 0,
#     sigma_t . tau = -mu dU1/dY (X, 0),
# so the slip s(X,t) = U1(X,0,t) and the tangential traction lambda(X,t) can be prescribed
# independently through cubic Hermite functions in Y that vanish at the clamped side Y = 1:
#     U1 = phi0(Y) s(X,t) + phi1(Y) (-lambda(X,t)/mu) + Y^2 (1-Y) r(X,t),   U2 = Y (1-Y) w(X,t),
#     phi0 = (1-Y)^2 (1+2Y)  (phi0(0)=1, phi0'(0)=0, phi0(1)=0),
#     phi1 = Y (1-Y)^2       (phi1(0)=0, phi1'(0)=1, phi1(1)=0).
# The Tresca law then only concerns the scalar pair (s, lambda): |lambda| <= g_a, s' = 0 where
# |lambda| < g_a, and lambda = -g_a sign(s') where s' != 0.

Xs, Ys = sp.symbols("X Y", real=True)
PHI0 = (1 - Ys) ** 2 * (1 + 2 * Ys)
PHI1 = Ys * (1 - Ys) ** 2


def local_field(s, lam_t, mu, r, w):
    U1 = PHI0 * s + PHI1 * (-lam_t / mu) + Ys ** 2 * (1 - Ys) * r
    U2 = Ys * (1 - Ys) * w
    return U1, U2


def to_global(U1, U2, c, sn, origin=(0, 0)):
    """Rotate a local field (X along (c, sn), Y along (-sn, c)) into global coordinates."""
    X_of = c * (x - origin[0]) + sn * (y - origin[1])
    Y_of = -sn * (x - origin[0]) + c * (y - origin[1])
    sub = {Xs: X_of, Ys: Y_of}
    U1g, U2g = U1.subs(sub), U2.subs(sub)
    return [c * U1g - sn * U2g, sn * U1g + c * U2g], X_of


UNIT_SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
SOLVER = {"method": "ssn", "tol": 1e-12, "max_iter": 500}


def case_elastic():
    E, nu = R(100), R(3, 10)
    u = [x * (1 + t) * sp.cos(y + x / 2) / 10,
         x * (1 - t / 2) * sp.sin(x * y + R(1, 2)) / 20 + x ** 2 * y / 40]
    return dict(
        name="mms_elastic", title="MMS (d): plain elasticity, smooth exact solution, no contact",
        header="""\
Plain plane-strain elasticity (no contact part), smooth exact solution
    u1 = x (1+t) cos(y + x/2) / 10
    u2 = x (1-t/2) sin(x y + 1/2) / 20 + x^2 y / 40
on the unit square, clamped at x = 0 (left), tractions g = sigma(u) n on bottom/right/top,
body force f = -div sigma(u). E = 100, nu = 0.3, rho = 10.
Each time step is an independent elastic solve (no history), so there is no time error.
Expected: energy / H1 error O(h), L2 error O(h^2) under refinement (refine = 0, 1, 2, ...).
Measured errors and rates: reference/cross_check.md and `tresca-cr study` on this scene.""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "neumann", "right": "neumann", "top": "neumann", "left": "dirichlet"},
        u=u, g_a=None, T=1, steps=2, expect={})


def case_front(slip_sign=1):
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    g0, A, w = R(1, 5), R(1, 20), R(1, 2)
    xi = R(1, 4) + R(1, 2) * t
    ga = g0 * (1 + Xs / 2)
    s = slip_sign * A * SStep((xi - Xs) / w, 0)
    delta = R(1, 4)                                # width over which the stick margin saturates
    lam_t = -ga + R(3, 2) * g0 * (SStep((Xs - xi) / delta, 0) + SStep((xi - w - Xs) / delta, 0))
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_front", title="MMS (a): travelling slip pulse on the bottom side (stick->slip->stick fronts)",
        header="""\
Moving stick-slip fronts on Gamma_C = bottom side y = 0 of the unit square (clamped top y = 1,
Neumann left/right). Exercises: h-convergence with moving fronts in both directions.
Slip zone at time t:  xi(t) - w < x < xi(t),  xi(t) = 1/4 + t/2,  w = 1/2,  T = 1
  (t = 0: 0 < x < 0.25;  t = 1: 0.25 < x < 0.75). Points 0.25 < x < 0.75 pass stick -> slip at the
  leading front; points 0 < x < 0.25 pass slip -> stick at the trailing front.
  slip        s(x,t)  = u1(x,0,t) = (1/20) S((xi(t)-x)/w),  S(c) = 10c^3-15c^4+6c^5 on [0,1], clamped
                        (s' >= 0: slip in +x; s' -> 0 continuously at both fronts)
  friction    g_a(x)  = (1/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) + (3/10)[S((x-xi)/d) + S((xi-w-x)/d)],  d = 1/4
                        (= -g_a in the slip zone; the stick margin rises like 10(z/d)^3 and
                        saturates at 3/10 within d = 1/4 of either front)
  u1 = phi0(y) s + phi1(y) (-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20,
  phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2.  E = 10, nu = 0.3 (mu = 50/13).
u(.,t) is C^2 (in H^3 even), so expected: energy/H1 error O(h), L2 error O(h^2).
Time: s' is continuous and vanishes at both fronts; the exact solution satisfies the backward-Euler
inclusion at the nodes except on the O(k) strip the trailing front crosses in a step, where the
traction defect is O(k^3): the energy error does not depend on N. The L2 error does a little at
coarse N (time/space cancellation) and settles for N >= 64, hence steps = 64 for the h study.
Measured errors and rates: reference/h_mms_front.md (make verify regenerates it).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=64,
        expect={"stick_to_slip": True, "slip_to_stick": True})


def case_stick_to_slip():
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    g0, A = R(1, 5), R(1, 10)
    xi = R(1, 5) + R(3, 5) * t
    ga = g0 * (1 + Xs / 2)
    s = A * PosPow(xi - Xs, 3)
    lam_t = -ga + g0 * PosPow(Xs - xi, 3)
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_stick_to_slip", title="MMS: advancing slip front, points only pass from stick to slip",
        header="""\
Advancing slip front on Gamma_C = bottom side y = 0 of the unit square (clamped top, Neumann left/right).
Slip zone at time t: 0 < x < xi(t), xi(t) = 1/5 + 3t/5 (t = 0: x < 0.2; t = 1: x < 0.8). Points only
ever pass from stick to slip, and slip is monotone (s' >= 0).
  slip        s(x,t) = u1(x,0,t) = (1/10) max(0, xi(t)-x)^3
  friction    g_a(x) = (1/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) + (1/5) max(0, x-xi(t))^3
  u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20,
  phi0 = (1-y)^2(1+2y), phi1 = y(1-y)^2.  E = 10, nu = 0.3.
FINDING to show: the exact u satisfies the backward-Euler step EXACTLY at every node (a point whose
slip increment over (t_{n-1}, t_n] is non-zero is slipping at t_n, so sigma_t(t_n) = -g_a there), so
the semi-discretisation in time has zero error: the error is independent of N (only the spatial O(h)
energy / O(h^2) L2 error remains, up to the O(h)-wide discrete front).
Measured errors, independent of N: reference/be_exact_stick_to_slip.md (make verify regenerates it).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=8,
        expect={"stick_to_slip": True, "slip_to_stick": False})


def case_rotated():
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    c, sn = R(4, 5), R(3, 5)                       # rotation by atan(3/4) = 36.87 deg, exact
    g0, A = R(1, 5), R(1, 10)
    xi = R(4, 5) - R(3, 5) * t                     # front moves towards X = 0
    ga = g0 * (1 + Xs / 2)
    s = -A * PosPow(Xs - xi, 3)                    # slip zone X > xi(t), slip in -tau direction
    lam_t = ga - g0 * PosPow(xi - Xs, 3)           # = +g_a in the slip zone
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, X_of = to_global(U1, U2, c, sn)
    corners = [[0, 0], [c, sn], [c - sn, sn + c], [-sn, c]]
    return dict(
        name="mms_rotated", title="MMS (b): contact on a rotated edge (36.87 deg), slip in the -tau direction",
        header="""\
Unit square rotated by theta = atan(3/4) = 36.87 deg (cos = 4/5, sin = 3/5, exact corners), so the
contact edge is not axis-aligned: Gamma_C = side c0->c1 ("bottom") from (0,0) to (0.8,0.6), outward
normal n = (3/5,-4/5), tau = (4/5,3/5). Clamped side "top" (c2->c3), Neumann "left" and "right".
Local coordinates X = (4x+3y)/5 (along Gamma_C), Y = (-3x+4y)/5 (into the body); u = R U(X,Y).
Slip zone at time t: xi(t) < X < 1, xi(t) = 4/5 - 3t/5 (t = 0: X > 0.8; t = 1: X > 0.2); the front
moves towards c0 and points only pass from stick to slip. Slip is in the -tau direction:
  slip        u.tau = U1(X,0,t) = -(1/10) max(0, X-xi(t))^3
  friction    g_a   = (1/5)(1 + X/2)
  traction    sigma_t.tau = +g_a(X) - (1/5) max(0, xi(t)-X)^3   (= +g_a in the slip zone)
  U1 = phi0(Y) s + phi1(Y)(-sigma_t.tau/mu) + Y^2(1-Y)(1+t)cos(X)/20,  U2 = Y(1-Y)(1+X)(1+t/2)/20.
E = 10, nu = 0.3. Expected: energy/H1 O(h), L2 O(h^2); as in mms_stick_to_slip backward Euler is
exact at the nodes (no time error). Exercises the normal/tangent handling on a slanted edge and the
negative slip sign.
Measured errors and rates: reference/h_mms_rotated.md (make verify regenerates it).""",
        E=E, nu=nu, corners=corners, cells=[4, 4], diagonal="second",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, X_of), T=1, steps=8,
        expect={"stick_to_slip": True, "slip_to_stick": False})


def case_stop(stops=True):
    E, nu = R(10), R(3, 10)
    lam_, mu = lame(E, nu)
    ts, m = R(1, 3), 30
    g0 = R(2, 5)
    ga = g0 * (1 + Xs / 2)
    a = R(3, 10) * (1 + Xs / 2)                    # slip rate for t < t*
    s = a * (t - PosPow(t - ts, 1)) if stops else a * t   # = a min(t, t*)
    ramp = m * (PosPow(t - ts, 1) - PosPow(t - ts - R(1, m), 1))   # = min(1, m max(0, t-t*))
    lam_t = -ga * (1 - ramp)
    r = (1 + t) * sp.cos(Xs) / 20
    wv = (1 + Xs) * (1 + t / 2) / 20
    U1, U2 = local_field(s, lam_t, mu, r, wv)
    u, _ = to_global(U1, U2, 1, 0)
    return dict(
        name="mms_stop", title="MMS (c): slip stops abruptly at t* = 1/3 (slip velocity jumps)",
        header="""\
Slip that stops abruptly at t* = 1/3 on Gamma_C = bottom side of the unit square (clamped top,
Neumann left/right). Exercises the O(k) time error of backward Euler.
  slip        s(x,t) = u1(x,0,t) = a(x) min(t, t*),  a(x) = (3/10)(1 + x/2)   (s' jumps a -> 0 at t*)
  friction    g_a(x) = (2/5)(1 + x/2)
  traction    sigma_t.tau = -g_a(x) (1 - min(1, 30 max(0, t-t*)))
              (= -g_a while slipping; leaves the bound linearly after t*, reaches 0 at t* + 1/30)
  u1 = phi0(y) s + phi1(y)(-sigma_t.tau/mu) + y^2(1-y)(1+t)cos(x)/20,  u2 = y(1-y)(1+x)(1+t/2)/20.
All of Gamma_C slips (in +x) for t < t* and sticks for t > t*. Data are Lipschitz in time, u is
Lipschitz (not C^1) in time, smooth in space. E = 10, nu = 0.3.
Time behaviour: for t_n < t* backward Euler is exact (constant traction at the bound, constant
slip rate). In the step t_{n-1} < t* < t_n the discrete solution sticks (for N >= 4 the traction
margin g_a min(1, 30 (t_n - t*)) exceeds the stiffness times the missing slip), so it misses the
slip a(x)(t* - t_{n-1}) = a(x) theta k, theta = frac(N t*/T), and keeps that error for all later
times: e(t_n) = theta k ||W|| for t_n > t*, W the elastic field of a unit-rate slip a(x) with zero
loads. Hence O(k), but theta = frac(N/3) alternates 1/3, 2/3 for N = 2^j, so observed rates alternate
~0 and ~2. Use N = 4^j (4, 16, 64, 256: theta = 1/3 always) or N = 2*4^j (theta = 2/3) and compute the
order with log ratio / log 4: E(T) is then the same for N = 4 and 8, 16 and 32, 64 and 128
(theta k = 1/12, 1/48, 1/192). Measured errors and rates: reference/k_study_mms_stop.md and
reference/joint_mms_stop.md (make verify regenerates them).""",
        E=E, nu=nu, corners=UNIT_SQUARE, cells=[4, 4], diagonal="first",
        kinds={"bottom": "contact", "right": "neumann", "top": "dirichlet", "left": "neumann"},
        u=u, g_a=ga.subs(Xs, x), T=1, steps=4, t_special=[ts],
        expect={"stick_to_slip": False, "slip_to_stick": True})


CASES = [case_front, case_rotated, case_stop, case_elastic, case_stick_to_slip]


# ---------------------------------------------------------------------------------------------
# 6. Derivation of all data
# ---------------------------------------------------------------------------------------------

def derive(case):
    E, nu = case["E"], case["nu"]
    lam_, mu = lame(E, nu)
    u = [sp.sympify(v) for v in case["u"]]
    G = grad_of(u)
    S = stress(G, lam_, mu)
    f = body_force(S)
    tractions = {}
    for side, kind in case["kinds"].items():
        if kind == "neumann":
            n = side_normal_exact(case["corners"], side)
            g = S * n
            tractions[side] = [g[0], g[1]]
    u0 = [v.subs(t, 0) for v in u]
    d = dict(case, lam=lam_, mu=mu, u=u, G=G, S=S, f=f, tractions=tractions, u0=u0)
    # every printed string, keyed by a label, with its sympy original
    sym = {"u1": u[0], "u2": u[1], "f1": f[0], "f2": f[1], "u0_1": u0[0], "u0_2": u0[1],
           "grad11": G[0, 0], "grad12": G[0, 1], "grad21": G[1, 0], "grad22": G[1, 1]}
    for side, g in tractions.items():
        sym["g_%s_1" % side], sym["g_%s_2" % side] = g
    if case["g_a"] is not None:
        sym["g_a"] = case["g_a"]
    d["sym"] = sym
    d["str"] = {k: ex(v) for k, v in sym.items()}
    for k, v in d["str"].items():
        problems = exmex_lint(v)
        if problems:
            raise CheckFailed("%s: %s violates exmex syntax rules: %s" % (case["name"], k, problems))
    return d


# ---------------------------------------------------------------------------------------------
# 7. Checks
# ---------------------------------------------------------------------------------------------

def require(cond, what):
    if not cond:
        raise CheckFailed(what)


def sample_points(d, rng, n=400):
    """Random points of the (possibly rotated) quadrilateral and random times in [0, T]."""
    c = np.array([[float(v) for v in p] for p in d["corners"]])
    a, b = rng.random(n), rng.random(n)
    P = ((1 - a) * (1 - b))[:, None] * c[0] + (a * (1 - b))[:, None] * c[1] + \
        (a * b)[:, None] * c[2] + ((1 - a) * b)[:, None] * c[3]
    T = rng.random(n) * float(d["T"])
    return P[:, 0], P[:, 1], T


def check_roundtrip(d, rng, log):
    """Printed string == sympy original at random points (strings re-parsed into sympy Max/Min)."""
    X, Y, T = sample_points(d, rng, 600)
    d["parsed"] = {}
    for k, s in d["str"].items():
        p = parse_exmex(s)
        d["parsed"][k] = p
        a, b = lam(d["sym"][k])(X, Y, T), lam(p)(X, Y, T)
        scale = max(1.0, np.max(np.abs(a)))
        err = np.max(np.abs(a - b)) / scale
        require(err < 1e-13, "%s: round trip of %s differs by %.3e" % (d["name"], k, err))
    log("round trip of %d printed expressions (max/min re-parsed)      ok" % len(d["str"]))


def check_exmex_binary(d, rng, binary, log):
    """Evaluate every printed string with a real exmex binary (reads 'expr\\tt\\tx\\ty' lines)."""
    X, Y, T = sample_points(d, rng, 40)
    lines, refs = [], []
    for k, s in d["str"].items():
        ref = lam(d["sym"][k])(X, Y, T)
        for i in range(len(X)):
            lines.append("%s\t%r\t%r\t%r" % (s, float(T[i]), float(X[i]), float(Y[i])))
            refs.append((k, ref[i]))
    out = subprocess.run([binary], input="\n".join(lines) + "\n", capture_output=True, text=True,
                         check=True).stdout.split("\n")
    worst = 0.0
    for (k, ref), o in zip(refs, out, strict=False):
        require(not o.startswith("ERR"), "%s: exmex rejects %s: %s" % (d["name"], k, o))
        worst = max(worst, abs(float(o) - ref) / max(1.0, abs(ref)))
    require(worst < 1e-12, "%s: exmex evaluation differs by %.3e" % (d["name"], worst))
    log("exmex binary evaluates all %d strings (max rel diff %.1e)        ok" % (len(d["str"]), worst))


def np_grad(d, which="parsed"):
    src = d[which]
    return [[lam(src["grad11"]), lam(src["grad12"])], [lam(src["grad21"]), lam(src["grad22"])]]


def stress_np(Gf, lam_, mu, X, Y, T):
    g = [[Gf[i][j](X, Y, T) for j in range(2)] for i in range(2)]
    tr = g[0][0] + g[1][1]
    s11 = lam_ * tr + 2 * mu * g[0][0]
    s22 = lam_ * tr + 2 * mu * g[1][1]
    s12 = mu * (g[0][1] + g[1][0])
    return s11, s12, s22


def check_derivatives(d, rng, log):
    """Independent finite-difference checks of the printed data: grad vs FD of u, f vs -div sigma(FD),
    u0 = u(.,0), Neumann traction = sigma(grad) n, all using the re-parsed strings."""
    P = d["parsed"]
    lam_, mu = float(d["lam"]), float(d["mu"])
    X, Y, T = sample_points(d, rng, 400)
    u = [lam(P["u1"]), lam(P["u2"])]
    Gf = np_grad(d)
    h = 1e-6
    worst = 0.0
    for i in range(2):
        for j, (dx, dy) in enumerate([(h, 0), (0, h)]):
            fd = (u[i](X + dx, Y + dy, T) - u[i](X - dx, Y - dy, T)) / (2 * h)
            g = Gf[i][j](X, Y, T)
            worst = max(worst, np.max(np.abs(fd - g)) / max(1e-2, np.max(np.abs(g))))
    require(worst < 1e-6, "%s: grad != FD of u (%.2e)" % (d["name"], worst))
    # f = -div sigma with sigma from the printed grad, by central differences
    h = 1e-5
    def sig(Xp, Yp):
        return stress_np(Gf, lam_, mu, Xp, Yp, T)
    sxp, sxm, syp, sym_ = sig(X + h, Y), sig(X - h, Y), sig(X, Y + h), sig(X, Y - h)
    div1 = (sxp[0] - sxm[0]) / (2 * h) + (syp[1] - sym_[1]) / (2 * h)
    div2 = (sxp[1] - sxm[1]) / (2 * h) + (syp[2] - sym_[2]) / (2 * h)
    f1, f2 = lam(P["f1"])(X, Y, T), lam(P["f2"])(X, Y, T)
    scale = max(1e-2, np.max(np.abs(f1)), np.max(np.abs(f2)))
    err = max(np.max(np.abs(f1 + div1)), np.max(np.abs(f2 + div2))) / scale
    require(err < 1e-5, "%s: equilibrium f + div sigma = %.2e (FD)" % (d["name"], err))
    # exact (symbolic) equilibrium with the parsed expressions
    lam_s, mu_s = d["lam"], d["mu"]
    Gp = sp.Matrix([[P["grad11"], P["grad12"]], [P["grad21"], P["grad22"]]])
    Sp = stress(Gp, lam_s, mu_s)
    fr = body_force(Sp)
    res = max(np.max(np.abs(lam(fr[0] - P["f1"])(X, Y, T))), np.max(np.abs(lam(fr[1] - P["f2"])(X, Y, T))))
    require(res < 1e-11 * scale, "%s: symbolic equilibrium residual %.2e" % (d["name"], res))
    # u0
    Z = np.zeros_like(X)
    e0 = max(np.max(np.abs(lam(P["u0_1"])(X, Y, Z) - u[0](X, Y, Z))),
             np.max(np.abs(lam(P["u0_2"])(X, Y, Z) - u[1](X, Y, Z))))
    require(e0 < 1e-14, "%s: u0 != u(.,0)" % d["name"])
    # Neumann tractions
    s = np.linspace(0, 1, 201)
    tt = np.linspace(0, float(d["T"]), 21)
    S_, TT = np.meshgrid(s, tt, indexing="ij")
    for side, kind in d["kinds"].items():
        a, b, n, tau = side_geometry(d["corners"], side)
        PX, PY = a[0] + S_ * (b[0] - a[0]), a[1] + S_ * (b[1] - a[1])
        if kind == "neumann":
            s11, s12, s22 = stress_np(Gf, lam_, mu, PX, PY, TT)
            g1 = lam(P["g_%s_1" % side])(PX, PY, TT)
            g2 = lam(P["g_%s_2" % side])(PX, PY, TT)
            err = max(np.max(np.abs(s11 * n[0] + s12 * n[1] - g1)), np.max(np.abs(s12 * n[0] + s22 * n[1] - g2)))
            require(err < 1e-12 * max(1, np.max(np.abs(g1)), np.max(np.abs(g2))),
                    "%s: traction on %s != sigma n (%.2e)" % (d["name"], side, err))
        if kind == "dirichlet":
            err = max(np.max(np.abs(u[0](PX, PY, TT))), np.max(np.abs(u[1](PX, PY, TT))))
            require(err < 1e-13, "%s: u != 0 on Dirichlet side %s (%.2e)" % (d["name"], side, err))
    log("grad = FD(u), f = -div sigma (FD and symbolic), u0, g = sigma n, u = 0 on Gamma_D   ok")


def check_contact(d, log):
    """Pointwise Tresca conditions on Gamma_C on a fine space-time grid (parsed expressions;
    velocities by sympy differentiation of the parsed u, independent of the PosPow/SStep rules)."""
    sides = [s for s, k in d["kinds"].items() if k == "contact"]
    if not sides:
        return
    P = d["parsed"]
    lam_, mu = float(d["lam"]), float(d["mu"])
    Gf = np_grad(d)
    u = [lam(P["u1"]), lam(P["u2"])]
    ud = [lam(sp.diff(P["u1"], t)), lam(sp.diff(P["u2"], t))]
    ud_custom = [lam(sp.diff(d["sym"]["u1"], t)), lam(sp.diff(d["sym"]["u2"], t))]
    ga_f = lam(P["g_a"])
    Tn = float(d["T"])
    times = set(np.linspace(0, Tn, 601).tolist())
    for ts in d.get("t_special", []):
        times |= {float(ts) - 1e-9, float(ts), float(ts) + 1e-9}
    times = np.array(sorted(times))
    for side in sides:
        a, b, n, tau = side_geometry(d["corners"], side)
        s = np.linspace(0, 1, 2001)
        S_, TT = np.meshgrid(s, times, indexing="ij")           # (space, time)
        PX, PY = a[0] + S_ * (b[0] - a[0]), a[1] + S_ * (b[1] - a[1])
        un = u[0](PX, PY, TT) * n[0] + u[1](PX, PY, TT) * n[1]
        require(np.max(np.abs(un)) < 1e-13, "%s: u.n != 0 on Gamma_C (%.2e)" % (d["name"], np.max(np.abs(un))))
        s11, s12, s22 = stress_np(Gf, lam_, mu, PX, PY, TT)
        sn1, sn2 = s11 * n[0] + s12 * n[1], s12 * n[0] + s22 * n[1]
        snn = sn1 * n[0] + sn2 * n[1]
        st1, st2 = sn1 - snn * n[0], sn2 - snn * n[1]             # sigma_t (vector)
        st_abs = np.hypot(st1, st2)
        ga = ga_f(PX, PY, TT)
        require(np.min(ga) > 0, "%s: g_a must be positive" % d["name"])
        require(np.all(ga == ga[:, :1]), "%s: g_a depends on t" % d["name"])
        v1, v2 = ud[0](PX, PY, TT), ud[1](PX, PY, TT)
        w1, w2 = ud_custom[0](PX, PY, TT), ud_custom[1](PX, PY, TT)
        vnd = max(np.max(np.abs(v1 - w1)), np.max(np.abs(v2 - w2)))
        require(vnd < 1e-12, "%s: time derivative (Max/Heaviside) != custom rule (%.2e)" % (d["name"], vnd))
        vn = v1 * n[0] + v2 * n[1]
        vt1, vt2 = v1 - vn * n[0], v2 - vn * n[1]
        vt_abs = np.hypot(vt1, vt2)
        ttol = 1e-11 * np.max(ga)
        vtol = 1e-11 * max(1e-3, np.max(vt_abs))
        # |sigma_t| <= g_a
        viol = np.max(st_abs - ga)
        require(viol <= ttol, "%s: |sigma_t| exceeds g_a by %.2e" % (d["name"], viol))
        # stick: |sigma_t| < g_a strictly  =>  u_t' = 0
        stick = st_abs < ga - ttol
        bad = np.max(vt_abs[stick]) if stick.any() else 0.0
        require(bad <= vtol, "%s: stick point with slip velocity %.2e" % (d["name"], bad))
        # slip: u_t' != 0  =>  |sigma_t| = g_a and u_t' = -theta sigma_t, theta >= 0
        slip = vt_abs > vtol
        if slip.any():
            gap = np.max(np.abs(st_abs[slip] - ga[slip]))
            require(gap <= ttol, "%s: slipping point with |sigma_t| != g_a (%.2e)" % (d["name"], gap))
            theta = -(vt1 * st1 + vt2 * st2)[slip] / st_abs[slip] ** 2
            require(np.min(theta) >= 0, "%s: slip velocity not opposite to sigma_t" % d["name"])
            res = np.max(np.hypot(vt1[slip] + theta * st1[slip], vt2[slip] + theta * st2[slip]))
            require(res <= vtol, "%s: u_t' not parallel to sigma_t (%.2e)" % (d["name"], res))
        # compatibility of u0: |sigma_t(u0)| <= g_a (t = 0 column)
        require(times[0] == 0 and np.max(st_abs[:, 0] - ga[:, 0]) <= ttol, "%s: u0 incompatible" % d["name"])
        # non-vacuity and expected kinds of transitions
        require(stick.mean() > 0.05 or d["name"] == "mms_stop", "%s: (almost) no stick samples" % d["name"])
        require(slip.mean() > 0.05, "%s: (almost) no slip samples" % d["name"])
        dsl = np.diff(slip.astype(int), axis=1)
        n_ss = int(np.sum(np.any(dsl == 1, axis=1)))            # points that go stick -> slip
        n_sk = int(np.sum(np.any(dsl == -1, axis=1)))           # points that go slip -> stick
        exp = d["expect"]
        require((n_ss > 0) == exp["stick_to_slip"], "%s: stick->slip transitions: %d" % (d["name"], n_ss))
        require((n_sk > 0) == exp["slip_to_stick"], "%s: slip->stick transitions: %d" % (d["name"], n_sk))
        st_tau = st1 * tau[0] + st2 * tau[1]
        log("Tresca on %s (%d x %d samples): u.n=0, |sig_t|<=g_a, stick, slip dir, u0   ok"
            % (side, len(s), len(times)))
        log("   stick %.0f%%, slipping %.0f%% of samples; %d points stick->slip, %d slip->stick; "
            "sigma_t.tau in [%.3g, %.3g], g_a in [%.3g, %.3g], max|slip rate| %.3g"
            % (100 * stick.mean(), 100 * slip.mean(), n_ss, n_sk, st_tau.min(), st_tau.max(),
               ga.min(), ga.max(), vt_abs.max()))


def run_checks(case, exmex_bin=None, log=print):
    rng = np.random.default_rng(20240611)          # fixed seed: deterministic
    d = derive(case)
    check_roundtrip(d, rng, log)
    if exmex_bin:
        check_exmex_binary(d, rng, exmex_bin, log)
    check_derivatives(d, rng, log)
    check_contact(d, log)
    return d


def selftest():
    """The checks must catch deliberately wrong data: every mutant below has to FAIL."""
    def scaled_ga(make, factor):
        c = make()
        c["g_a"] = c["g_a"] * factor
        return c

    def shifted(make, du2):
        c = make()
        c["u"] = [c["u"][0], c["u"][1] + du2]
        return c

    mutants = {
        "g_a 1% too small (|sigma_t| > g_a)": lambda: scaled_ga(case_front, R(99, 100)),
        "g_a 1% too large (slip below the bound)": lambda: scaled_ga(case_front, R(101, 100)),
        "slip along sigma_t (wrong direction)": lambda: case_front(slip_sign=-1),
        "slip continues after traction leaves the bound": lambda: case_stop(stops=False),
        "normal displacement on Gamma_C and Gamma_D": lambda: shifted(case_stick_to_slip, t * x / 100),
        "unrotated g_a on the rotated edge": lambda: dict(case_rotated(), g_a=R(1, 5) * (1 + x / 2)),
    }
    for what, make in mutants.items():
        try:
            run_checks(make(), log=lambda msg: None)
        except CheckFailed as err:
            print("   selftest: %-50s caught: %s" % (what, err))
            continue
        raise CheckFailed("selftest: mutant '%s' passed the checks" % what)


# ---------------------------------------------------------------------------------------------
# 8. Scene TOML
# ---------------------------------------------------------------------------------------------

def toml_float(v):
    return repr(float(v))


def write_toml(d, path):
    st = d["str"]
    L = ["# " + line if line else "#" for line in d["header"].split("\n")]
    L = ["# Manufactured solution -- GENERATED by verification/mms/derive.py, do not edit by hand."] + L
    L += ["#", "# Regenerate: .venv/bin/python verification/mms/derive.py", ""]
    L.append('title = "%s"' % d["title"])
    L += ["", "[mesh]",
          "corners  = [%s]" % ", ".join("[%s, %s]" % (toml_float(p[0]), toml_float(p[1])) for p in d["corners"]),
          "cells    = [%d, %d]" % tuple(d["cells"]),
          'diagonal = "%s"' % d["diagonal"],
          "refine   = 0", "",
          "[material]", "E  = %s" % toml_float(d["E"]), "nu = %s" % toml_float(d["nu"])]
    for side in ["bottom", "right", "top", "left"]:
        kind = d["kinds"][side]
        L += ["", "[[boundary]]", 'name = "%s"' % side, 'kind = "%s"' % kind]
        if kind == "neumann":
            L.append('traction = ["%s", "%s"]' % (st["g_%s_1" % side], st["g_%s_2" % side]))
        if kind == "contact":
            L.append('g_a  = "%s"' % st["g_a"])
    L += ["", "[loads]", 'f = ["%s", "%s"]' % (st["f1"], st["f2"]),
          "", "[initial]", 'u0 = ["%s", "%s"]' % (st["u0_1"], st["u0_2"]),
          "", "[time]", "T = %s" % toml_float(d["T"]), "steps = %d" % d["steps"],
          "", "[discretisation]", "rho = 10.0",
          "", "[solver]", 'method   = "%s"' % SOLVER["method"], "tol      = %g" % SOLVER["tol"],
          "max_iter = %d" % SOLVER["max_iter"],
          "", "[exact]", 'u    = ["%s", "%s"]' % (st["u1"], st["u2"]),
          'grad = [["%s", "%s"],\n        ["%s", "%s"]]' % (st["grad11"], st["grad12"], st["grad21"], st["grad22"]),
          ""]
    text = "\n".join(L)
    path.write_text(text)
    return text


def check_toml(path, d):
    """The written file parses as TOML and carries exactly the derived strings."""
    import tomllib
    doc = tomllib.loads(path.read_text())
    st = d["str"]
    require(doc["exact"]["u"] == [st["u1"], st["u2"]], "%s: TOML exact.u mismatch" % path)
    require(doc["loads"]["f"] == [st["f1"], st["f2"]], "%s: TOML f mismatch" % path)
    require(doc["exact"]["grad"] == [[st["grad11"], st["grad12"]], [st["grad21"], st["grad22"]]],
            "%s: TOML grad mismatch" % path)


# ---------------------------------------------------------------------------------------------
# 9. Main
# ---------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="derive and check only, write nothing")
    ap.add_argument("--exmex", metavar="BIN", help="binary evaluating 'expr\\tt\\tx\\ty' lines with exmex")
    ap.add_argument("--no-selftest", action="store_true", help="skip the check that wrong data are rejected")
    ap.add_argument("--out", default=str(CASES_DIR), help="output directory (default verification/cases)")
    args = ap.parse_args()
    out = pathlib.Path(args.out)
    derived = []
    try:
        for make in CASES:
            case = make()
            print("== %s: %s" % (case["name"], case["title"]))
            def log(msg):
                return print("   " + msg)
            d = run_checks(case, args.exmex, log)
            log("longest printed expression: %d characters" % max(len(v) for v in d["str"].values()))
            derived.append(d)
        if not args.no_selftest:
            print("== selftest: deliberately wrong data must be rejected")
            selftest()
    except (CheckFailed, NotPrintable) as err:
        print("\nCHECK FAILED: %s" % err, file=sys.stderr)
        sys.exit(1)
    if args.check:
        print("all checks passed (nothing written)")
        return
    out.mkdir(parents=True, exist_ok=True)
    for d in derived:
        path = out / (d["name"] + ".toml")
        write_toml(d, path)
        check_toml(path, d)
        print("wrote %s" % path)
    print("all checks passed")


if __name__ == "__main__":
    main()

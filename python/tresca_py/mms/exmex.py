"""Printers from sympy to exmex syntax (the scene expression language, read back by ``tresca_py.expr``).

``ex``: exact printer of the manufactured cases (rationals only, no unary minus, every non-atom in
parentheses, no nested min/max). ``sstr`` : the shorter float printer of the plain-elasticity scenes
(verification/cases/gen_elastic.py).
"""
import sympy as sp

from tresca_py.mms.blocks import PosPow, SStep, Step

R = sp.Rational

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
    if isinstance(e, sp.atan2):
        return "atan2(" + ex(e.args[0]) + "," + ex(e.args[1]) + ")"
    if e.func in _FUNCS:
        return _FUNCS[e.func] + "(" + ex(e.args[0]) + ")"
    raise NotPrintable("no exmex form for %s" % e.func)


def sstr(e):
    """sympy's str printer with ``^`` for powers and PI for pi, at full precision; a leading minus is
    written ``0 + -...`` so the text never starts with a unary minus (gen_elastic's format)."""
    s = sp.sstr(e, full_prec=True)
    s = s.replace("**", "^").replace("pi", "PI")
    return "0 + " + s if s.startswith("-") else s


def factored(e):
    """sympy's factored form with ``^`` for powers (integer coefficients only): the printer of
    verification/cases/near_incompressible.toml, whose strings the solvers have read since it was written."""
    return str(sp.factor(e)).replace("**", "^")

"""A bound on the rounding error of a scene expression's value in f64, the rule of ``src/scene/expr/rounding.rs``
(stated there: running error analysis, to first order in the unit roundoff u = 2⁻⁵³) applied along the sympy
tree of ``tresca_py.expr``, vectorised over the points:

* a number: 0 for an integer below 2⁵³, else 2u|c|; a variable: 0;
* a sum (sympy's are n-ary: summed left to right): e_a + e_b + u|v| at each addition; a product likewise
  |a|e_b + |b|e_a + e_a e_b + u|v|; ``1/a`` (``a^-1``): |v|e_a/(|a| − e_a) + u|v|;
* ``a^b``: |v|(|b|e_a/a + |ln a|e_b) + 2u|v| for a > 0, else for an integer b as a smooth function of a;
* a smooth function: |f'(a)|e_a + 2u|v| (f' by a centred difference over at least e_a); ``floor``, ``ceil``:
  the jump |f(a + e_a) − f(a − e_a)|; ``abs``: e_a; ``min``, ``max``: the larger bound; a piecewise function
  (signum, round, trunc, cbrt): the chosen branch's bound, both branches' and their difference where its
  condition's argument lies within its bound of 0.

Sympy's tree is not exmex's (it groups sums and products and writes a − b as a + (−1)·b), so the two bounds
differ in their last terms; both bound the rounding of the value. ``inf`` where the analysis does not apply
(a division by an interval holding 0, a pole, a node it does not know).
"""
import numpy as np

U = np.finfo(float).eps / 2


def _number(c):
    v = float(c)
    exact = v == int(v) and abs(v) < 2.0 ** 53 if np.isfinite(v) else False
    return v, 0.0 if exact else 2 * U * abs(v)


def _slope(f, a, e):
    """|f'(a)| by a centred difference over h = max(e, 1e-8|a|) (one-sided at the edge of f's domain)."""
    h = np.maximum(np.maximum(e, 1e-8 * np.abs(a)), np.finfo(float).tiny)
    with np.errstate(all="ignore"):
        lo, mid, hi = f(a - h), f(a), f(a + h)
        ds = [(hi - lo) / (2 * h), (hi - mid) / h, (mid - lo) / h]
    out = np.full(np.broadcast(a, h).shape, np.inf)
    for d in reversed(ds):                      # the first finite one, in this order
        out = np.where(np.isfinite(d), np.abs(d), out)
    return out


def _add(a, b):
    v = a[0] + b[0]
    return v, a[1] + b[1] + U * np.abs(v)


def _mul(a, b):
    v = a[0] * b[0]
    return v, np.abs(a[0]) * b[1] + np.abs(b[0]) * a[1] + a[1] * b[1] + U * np.abs(v)


def _pow(a, b, v):
    (av, ae), (bv, be) = a, b
    own = U * np.abs(v)
    with np.errstate(all="ignore"):
        positive = np.abs(v) * (np.abs(bv) * ae / av + np.abs(np.log(np.abs(av))) * be) + 2 * own
        smooth = _slope(lambda s: np.power(s, bv), av, ae) * ae + 2 * own
        inverse = np.where(np.abs(av) > ae, np.abs(v) * ae / (np.abs(av) - ae), np.inf) + own
    integer = np.floor(bv) == bv
    out = np.where(av > 0, positive, np.where(integer, smooth, np.inf))
    return np.where((bv == -1) & (be == 0), inverse, out)


def value_and_bound(sym, x, y, t):
    """(value, rounding bound) of the sympy expression ``sym`` at the points (x, y) and time t (module doc)."""
    import sympy as S
    from tresca_py.expr import symbols
    vars_ = dict(zip(symbols(), (np.asarray(x, float), np.asarray(y, float), np.float64(t)), strict=True))

    def walk(s):
        if s in vars_:
            return vars_[s], 0.0
        if s.is_Number or s.is_NumberSymbol:
            return _number(s)
        args = [walk(a) for a in s.args] if not isinstance(s, S.Piecewise) else None
        with np.errstate(all="ignore"):
            if isinstance(s, S.Add):
                return _fold(_add, args)
            if isinstance(s, S.Mul):
                return _fold(_mul, args)
            if isinstance(s, S.Pow):
                v = np.power(args[0][0], args[1][0])
                return v, _pow(args[0], args[1], v)
            if isinstance(s, S.Piecewise):
                return _piecewise(s, walk)
            return _function(s, args)

    v, e = walk(sym)
    e = np.asarray(e, float)
    return v, np.where(np.isnan(e), np.inf, e)


def _fold(op, args):
    out = args[0]
    for a in args[1:]:
        out = op(out, a)
    return out


def _function(s, args):
    """A function node of ``tresca_py.expr._names``: its value and bound (module doc)."""
    import sympy as S
    name = type(s).__name__
    if isinstance(s, (S.Min, S.Max)):
        f = np.minimum if isinstance(s, S.Min) else np.maximum
        return _fold(lambda a, b: (f(a[0], b[0]), np.maximum(a[1], b[1])), args)
    if isinstance(s, S.atan2):
        (a, ea), (b, eb) = args
        v, r2 = np.arctan2(a, b), a * a + b * b
        return v, np.where(r2 > 0, (np.abs(b) * ea + np.abs(a) * eb) / r2 + 2 * U * np.abs(v), np.inf)
    (a, ea), = args
    if isinstance(s, S.Abs):
        return np.abs(a), ea
    if isinstance(s, (S.floor, S.ceiling)):
        f = np.floor if isinstance(s, S.floor) else np.ceil
        return f(a), np.abs(f(a + ea) - f(a - ea))
    f = {"sin": np.sin, "cos": np.cos, "tan": np.tan, "asin": np.arcsin, "acos": np.arccos, "atan": np.arctan,
         "sinh": np.sinh, "cosh": np.cosh, "tanh": np.tanh, "asinh": np.arcsinh, "acosh": np.arccosh,
         "atanh": np.arctanh, "exp": np.exp, "log": np.log}.get(name)
    if f is None:
        return np.asarray(float(s.evalf()) if not s.free_symbols else np.nan), np.inf
    v = f(a)
    return v, _slope(f, a, ea) * ea + 2 * U * np.abs(v)


def _piecewise(s, walk):
    """``Piecewise((A, c < 0), (B, True))`` of ``tresca_py.expr``: the chosen branch's bound, and where c lies
    within its bound of 0 both branches' and their difference."""
    (a_expr, cond), (b_expr, _) = s.args
    (av, ae), (bv, be) = walk(a_expr), walk(b_expr)
    cv, ce = walk(cond.lhs - cond.rhs)
    v = np.where(cv < 0, av, bv)
    e = np.where(cv < 0, ae, be)
    unsure = np.abs(cv) <= ce
    return v, np.where(unsure, np.maximum(ae, be) + np.abs(av - bv), e)

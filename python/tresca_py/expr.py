"""The one reading of scene expressions (exmex syntax, src/scene/expr) into sympy and numpy.

Every Python user of scene expressions (the scikit-fem and dolfinx re-implementations, the
manufactured-solution derivation, the tests) reads them here, so all of them agree with the Rust
solver on what a string means and on which strings are refused:

* ``lint`` is src/scene/expr/lint.rs line for line: it refuses a unary minus before a power
  (exmex reads ``-x^2`` as ``(-x)^2``), chained powers (``2^x^2`` is ``(2^x)^2`` in exmex) and a
  min/max/atan2 nested inside another (exmex cannot parse it).
* ``parse`` then reads what is left with sympy, with exmex's operator table: ``^`` is power, constants
  ``PI``/``pi``/``π``, ``E``/``e``, ``TAU``/``τ``; unary functions ``abs signum sin cos tan asin acos atan
  sinh cosh tanh asinh acosh atanh floor round ceil trunc fract exp sqrt cbrt ln log log2 log10``;
  two-argument ``atan2 min max`` (exactly two arguments). Their values are those of Rust's ``f64``
  methods: ``signum(0) = +1``, ``round`` rounds half away from zero, ``fract(a) = a - trunc(a)``,
  ``cbrt`` is the real cube root, ``log`` is ``ln``.
* What exmex refuses is refused too: unknown names and variables (only x, y, t), ``**``, ``%``, ``!``,
  implicit products (``2x``), a constant that is not finite (``1/0``), min/max/atan2 with other than two
  arguments. One reading is stricter than exmex's: a function must take its argument in parentheses
  (exmex also reads ``sin x`` and ``exp -x``, with its own binding of the prefix operator).

``signum``, ``round``, ``trunc`` and ``cbrt`` are sympy ``Piecewise`` expressions, so they print to
numpy and to UFL conditionals (dolfinx_cr.ufl_expr) with the same values.
"""
from __future__ import annotations

import functools
import re

import numpy as np

from tresca_py.errors import InputError


class ExprError(InputError):
    """An expression the solver refuses; the message names the scene key and the text."""


_BINARY = ("min", "max", "atan2")


def _tokens(text):
    """lint.rs's tokens (atom ident binary open close comma op:<c>) and the text as handed to exmex."""
    toks = []                                   # kinds: atom ident binary open close comma op:<c>
    i, n = 0, len(text)
    out = []
    while i < n:
        c = text[i]
        if c.isspace():
            out.append(c)
            i += 1
        elif c.isdigit() or c == ".":
            j = i
            while j < n and (text[j].isdigit() or text[j] == "."):
                j += 1
            if j < n and text[j] in "eE":
                k = j + 1
                if k < n and text[k] in "+-":
                    k += 1
                if k < n and text[k].isdigit():
                    while k < n and text[k].isdigit():
                        k += 1
                    j = k
            lit = text[i:j]
            try:
                float(lit)
            except ValueError:
                raise ExprError(f"malformed number `{lit}`") from None
            out.append(lit)
            toks.append("atom")
            i = j
        elif c.isalnum() or c == "_":
            j = i
            while j < n and (text[j].isalnum() or text[j] == "_"):
                j += 1
            name = text[i:j]
            out.append("PI" if name == "pi" else name)
            toks.append("binary" if name in _BINARY else "ident")
            i = j
        else:
            out.append(c)
            toks.append({"(": "open", ")": "close", ",": "comma"}.get(c, "op:" + c))
            i += 1
    return toks, "".join(out)


def lint(text: str) -> str:
    """src/scene/expr/lint.rs: refuse the readings exmex makes unlike mathematics; return the text as
    handed to exmex (``pi`` written ``PI``; scientific literals are left as they are, Python reads them).
    Raises ``ExprError`` with the Rust message."""
    toks, normalised = _tokens(text)

    def skip_operand(i):
        j = i
        if j < len(toks) and toks[j] in ("ident", "binary") and j + 1 < len(toks) and toks[j + 1] == "open":
            j += 1
        if j < len(toks) and toks[j] == "open":
            depth = 0
            while j < len(toks):
                if toks[j] == "open":
                    depth += 1
                elif toks[j] == "close":
                    depth -= 1
                    if depth == 0:
                        return j + 1
                j += 1
            return j
        return j + 1

    calls, depth = [], 0
    for tk in toks:
        if tk == "open":
            depth += 1
        elif tk == "close":
            depth = max(depth - 1, 0)
            if calls and calls[-1] == depth:
                calls.pop()
        elif tk == "binary":
            if calls:
                raise ExprError("exmex cannot nest min/max/atan2 inside another min/max/atan2; "
                                "write max(a, b) as (a + b + abs(a - b))/2")
            calls.append(depth)
    at = lambda j: toks[j] if 0 <= j < len(toks) else None  # noqa: E731
    for i, tk in enumerate(toks):
        unary = tk == "op:-" and (i == 0 or toks[i - 1] in ("open", "comma") or toks[i - 1].startswith("op:"))
        if unary and at(skip_operand(i + 1)) == "op:^":
            raise ExprError("ambiguous unary minus before a power: exmex reads -a^b as (-a)^b; "
                            "write -(a^b) or (-a)^b")
        if tk == "op:^":
            j = i + 1
            while at(j) in ("op:-", "op:+"):
                j += 1
            if at(skip_operand(j)) == "op:^":
                raise ExprError("chained powers: exmex reads a^b^c as (a^b)^c; parenthesise, e.g. a^(b^c)")
    return normalised


# characters exmex's float operators are written with (plus Python's float literal syntax)
_ALLOWED = re.compile(r"^[0-9A-Za-z_.\s+\-*/^(),πτ]*$")
_FUNCTIONS = ("abs", "signum", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh",
              "acosh", "atanh", "floor", "round", "ceil", "trunc", "fract", "exp", "sqrt", "cbrt", "ln", "log",
              "log2", "log10") + _BINARY


@functools.cache
def _names():
    """The operator table (exmex's FloatOpsFactory, src/scene/expr/sym.rs) as sympy callables."""
    import sympy as S
    x, y, t = symbols()

    def two(name, f):
        def call(*args):
            if len(args) != 2:
                raise ExprError(f"{name} takes exactly two arguments, got {len(args)}")
            return f(*args)
        return call

    def signum(a):
        return S.Piecewise((-1, a < 0), (1, True))          # f64::signum: +1 at 0

    def trunc(a):
        return S.Piecewise((S.ceiling(a), a < 0), (S.floor(a), True))

    def rnd(a):                                            # f64::round: half away from zero
        return S.Piecewise((-S.floor(S.Rational(1, 2) - a), a < 0), (S.floor(a + S.Rational(1, 2)), True))

    def cbrt(a):
        return S.Piecewise((-((-a) ** S.Rational(1, 3)), a < 0), (a ** S.Rational(1, 3), True))

    return {
        "x": x, "y": y, "t": t, "PI": S.pi, "pi": S.pi, "π": S.pi, "E": S.E, "e": S.E, "TAU": 2 * S.pi, "τ": 2 * S.pi,
        "abs": S.Abs, "signum": signum, "sin": S.sin, "cos": S.cos, "tan": S.tan, "asin": S.asin,
        "acos": S.acos, "atan": S.atan, "sinh": S.sinh, "cosh": S.cosh, "tanh": S.tanh, "asinh": S.asinh,
        "acosh": S.acosh, "atanh": S.atanh, "floor": S.floor, "round": rnd, "ceil": S.ceiling,
        "trunc": trunc, "fract": lambda a: a - trunc(a), "exp": S.exp, "sqrt": S.sqrt, "cbrt": cbrt,
        "ln": S.log, "log": S.log, "log2": lambda a: S.log(a) / S.log(2), "log10": lambda a: S.log(a) / S.log(10),
        "atan2": two("atan2", S.atan2), "min": two("min", S.Min), "max": two("max", S.Max),
    }


def symbols():
    """The sympy symbols x, y, t (real) every reading uses."""
    import sympy
    return sympy.symbols("x y t", real=True)


def parse(text, key="expression"):
    """Read an exmex expression string in x, y, t into sympy; ``ExprError`` names ``key`` otherwise."""
    import sympy
    from sympy.core.function import AppliedUndef
    from sympy.parsing.sympy_parser import parse_expr, standard_transformations
    if not isinstance(text, str) or not text.strip():
        raise ExprError(f"{key}: expected a non-empty expression string, got {text!r}")
    try:
        lint(text)
        if not _ALLOWED.match(text) or "**" in text:
            bad = sorted(set(re.sub(r"[0-9A-Za-z_.\s+\-*/^(),πτ]", "", text))) or ["**"]
            raise ExprError(f"cannot parse: {''.join(bad)!r} is no exmex operator")
        names = _names()
        for m in re.finditer(r"[A-Za-z_πτ][A-Za-z0-9_]*", text):
            f = m.group(0)
            if f in _FUNCTIONS and not text[m.end():].lstrip().startswith("("):
                raise ExprError(f"write the argument of {f} in parentheses, {f}(...)")
    except ExprError as err:
        raise ExprError(f"{key}: {text!r}: {err}") from None
    gdict = {"Integer": sympy.Integer, "Float": sympy.Float, "Rational": sympy.Rational,
             "Symbol": sympy.Symbol, "Function": sympy.Function, "__builtins__": {}}
    try:
        expr = parse_expr(text.replace("^", "**"), local_dict=dict(names), global_dict=gdict,
                          transformations=standard_transformations, evaluate=True)
    except ExprError as err:
        raise ExprError(f"{key}: {text!r}: {err}") from None
    except Exception as err:  # sympy raises many types
        raise ExprError(f"{key}: cannot parse expression {text!r}: {err}") from None
    if not isinstance(expr, sympy.Expr):
        raise ExprError(f"{key}: {text!r} is not a scalar expression")
    bad = expr.atoms(AppliedUndef)
    if bad:
        raise ExprError(f"{key}: unknown function(s) {sorted(str(b.func) for b in bad)} in {text!r}")
    extra = expr.free_symbols - set(symbols())
    if extra:
        raise ExprError(f"{key}: unknown variable(s) {sorted(map(str, extra))} in {text!r} "
                        "(only x, y, t are allowed)")
    if not expr.free_symbols and not expr.is_finite:
        raise ExprError(f"{key}: {text!r} evaluates to {expr}")
    return expr


class Expr:
    """A scalar expression of (x, y, t): ``.sym`` (sympy), ``__call__`` (numpy, broadcasting)."""

    def __init__(self, text, key="expression"):
        import sympy
        self.text, self.key = str(text), key
        self.sym = parse(text, key)
        self.symbols = symbols()
        self._f = sympy.lambdify(self.symbols, self.sym, modules="numpy")

    @property
    def is_zero(self):
        return self.sym == 0

    @property
    def depends_on_t(self):
        return self.symbols[2] in self.sym.free_symbols

    def rounding(self, x, y, t):
        """A bound on the rounding error of the values at (x, y, t), broadcast (``tresca_py.rounding``)."""
        from tresca_py.rounding import value_and_bound
        _, e = value_and_bound(self.sym, x, y, t)
        return np.broadcast_to(e, np.broadcast(np.asarray(x), np.asarray(y)).shape).copy()

    def __call__(self, x, y, t):
        """The values at (x, y, t), broadcast; ``ExprError`` naming the expression, the point and the value
        where one is not finite (Rust: ``value inf at (x=…, y=…, t=…)``, src/scene/expr/mod.rs). t enters as
        numpy's float64, so a part in t alone has f64's IEEE values as in Rust (1/(t - 0.5) at t = 0.5 is inf,
        (t - 1)^0.3 at t = 0 is NaN), where Python's float would raise or turn complex."""
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float)
        try:
            with np.errstate(all="ignore"):
                val = np.asarray(self._f(x, y, np.float64(t)), dtype=float)
        except (ArithmeticError, ValueError, TypeError) as e:       # not expected: IEEE gives inf/NaN instead
            at = f"(x, y) = ({float(x):.6g}, {float(y):.6g}), " if x.size == 1 == y.size else ""
            raise ExprError(f"{self.key}: expression {self.text!r} cannot be evaluated at {at}t = {float(t):.6g}: "
                            f"{e}") from None
        val = np.broadcast_to(val, np.broadcast(x, y).shape).copy()
        if not np.all(np.isfinite(val)):
            k = np.unravel_index(np.argmin(np.isfinite(val)), val.shape)
            xk, yk = np.broadcast_to(x, val.shape)[k], np.broadcast_to(y, val.shape)[k]
            raise ExprError(f"{self.key}: expression {self.text!r} has the value {val[k]} at "
                            f"(x, y) = ({xk:.6g}, {yk:.6g}), t = {float(t):.6g}")
        return val


class VecExpr:
    """A 2-vector of ``Expr``; ``__call__`` returns an array with leading axis 2."""

    def __init__(self, texts, key):
        if not isinstance(texts, (list, tuple)) or len(texts) != 2:
            raise ExprError(f"{key}: expected a list of two expression strings, got {texts!r}")
        self.comps = [Expr(s, f"{key}[{i}]") for i, s in enumerate(texts)]

    @property
    def is_zero(self):
        return all(c.is_zero for c in self.comps)

    @property
    def depends_on_t(self):
        return any(c.depends_on_t for c in self.comps)

    def __call__(self, x, y, t):
        return np.stack([c(x, y, t) for c in self.comps])

    def rounding(self, x, y, t):
        return np.stack([c.rounding(x, y, t) for c in self.comps])

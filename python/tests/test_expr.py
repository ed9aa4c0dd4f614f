"""The expression reading (tresca_py.expr): values of exmex's functions and constants, signum(0) = +1, and
the same verdict as the Rust solver (`tresca-cr check`) on accepted and refused expressions."""
import math
import os

import numpy as np
import pytest

from conftest import run
from tresca_py.expr import Expr, ExprError, VecExpr, lint

SCENE = """[mesh]
corners = [[0, 0], [1, 0], [1, 1], [0, 1]]
cells = [2, 2]
[material]
E = 1.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
[[boundary]]
name = "right"
kind = "neumann"
[[boundary]]
name = "top"
kind = "neumann"
[[boundary]]
name = "bottom"
kind = "neumann"
[loads]
f = ['{expr}', '0']
[time]
T = 1.0
steps = 2
"""

ACCEPTED = ["2*-x", "pi*x", "1.5e-1*x", "sin(x)^2", "TAU*x", "π*x", "cbrt(x)", "x^-2 + 1", "(x)", "abs(-x)^2",
            "log10(x+1)", "min(x, y)^2", "atan2(y, x+1)", "signum(x - 0.5)", "floor(2*x) + round(x) + trunc(y)",
            "fract(x) + ceil(y) + asinh(x) + log2(x + 1) + E + e"]
REFUSED = ["-x^2", "min(x, max(y, 1))", "min(x,y,1)", "x**2", "x!", "x % 2", "1/0", "2^x^2", "2x", "x y",
           "-(x)^2", "a", "-min(x,y)^2", "", "foo(x)", "x^", "1 +", "atan2(x, min(y, 1))", "2*-sin(x)^2"]


def test_the_system_shall_evaluate_exmex_functions_and_constants_as_rust_f64_does():
    e = Expr("2^3*sin(PI*x) + max(x, y) - min(1, t) + ln(e) + log(E) + signum(-2) + atan2(y, x)"
             " + sqrt(abs(-4)) + floor(2.5) + tanh(0) + sinh(0) + cosh(0) + exp(0) + 1.5e-1 + cbrt(-8)"
             " + round(-2.5) + trunc(-1.5) + fract(-1.25) + log10(100) + log2(8) + TAU", "k")
    x, y, t = 0.5, 1.0, 2.0
    ref = (8 * math.sin(math.pi * x) + max(x, y) - min(1, t) + 1 + 1 - 1 + math.atan2(y, x) + 2 + 2 + 0 + 0 + 1
           + 1 + 0.15 - 2 - 3 - 1 - 0.25 + 2 + 3 + 2 * math.pi)
    # a few roundings of terms of size <= 10: 1e-13 absolute
    assert abs(e(x, y, t) - ref) < 1e-13


def test_the_system_shall_read_signum_of_zero_as_plus_one():
    e = Expr("signum(x)", "k")
    assert e(np.array([-1.0, 0.0, 2.0]), 0.0, 0.0).tolist() == [-1.0, 1.0, 1.0]


def test_the_system_shall_detect_literal_zero_vectors():
    assert VecExpr(["0", "0*x"], "f").is_zero
    assert not VecExpr(["t", "0"], "g").is_zero


def test_the_system_shall_refuse_what_the_rust_lint_refuses_with_its_message():
    with pytest.raises(ExprError, match="unary minus before a power"):
        lint("-x^2")
    with pytest.raises(ExprError, match="chained powers"):
        lint("2^x^-2")
    with pytest.raises(ExprError, match="cannot nest"):
        lint("max(0, min(x, 1))")
    assert lint("pi*(-x)^2 + 2^-x") == "PI*(-x)^2 + 2^-x"


def test_the_system_shall_refuse_a_function_argument_without_parentheses():
    # exmex also reads `sin x`; the Python reading is stricter (documented in tresca_py.expr)
    with pytest.raises(ExprError, match="parentheses"):
        Expr("sin x", "k")


@pytest.mark.parametrize("text", ACCEPTED + REFUSED)
def test_the_system_shall_accept_and_refuse_expressions_as_the_rust_solver_does(text, rust_bin, tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(SCENE.format(expr=text))
    p = run([rust_bin, "check", str(path)])
    try:
        Expr(text, "f")
        python_ok = True
    except ExprError:
        python_ok = False
    assert python_ok == (p.returncode == 0), f"{text!r}: Rust: {p.stderr.strip() or 'accepted'}"
    assert os.path.exists(path)


# parts in t alone where Rust's f64 gives inf or NaN and Python's float would raise (ZeroDivisionError,
# OverflowError) or turn complex; x and y are arrays, as the solvers pass them
# (text, t where it is not finite, its value there, a t where it is finite)
IEEE = [("1/(t-0.5)", 0.5, "inf", 0.25), ("2^(1000*t) + x", 2.0, "inf", 0.5), ("(t-1)^0.3 + y", 0.0, "nan", 2.0)]


@pytest.mark.parametrize("text, t, value, t_ok", IEEE)
def test_the_system_shall_name_an_expression_whose_part_in_t_is_not_finite_with_the_point(text, t, value, t_ok):
    e = Expr(text, "[loads] f[0]")
    x, y = np.array([0.25, 0.75]), np.array([0.5, 0.5])
    with pytest.raises(ExprError) as err:
        e(x, y, t)
    assert (
        str(err.value) == f"[loads] f[0]: expression {text!r} has the value {value} at (x, y) = (0.25, 0.5), t = {t:g}"
    )
    assert np.all(np.isfinite(e(x, y, t_ok)))        # the same expression where f64 has a value: no error


def test_the_system_shall_stop_a_run_where_a_load_is_not_finite_as_the_rust_solver_does(rust_bin, tmp_path):
    """f = 1/(t - 0.5) at the time node t = 0.5: Rust and the scikit-fem re-implementation both stop with one
    error line naming the expression, the value inf and the time; no traceback."""
    from tresca_py.common import PY, SCRIPTS
    path = tmp_path / "s.toml"
    path.write_text(SCENE.format(expr="1/(t-0.5)"))
    p = run([rust_bin, "run", str(path), "-o", str(tmp_path / "r.h5"), "-q"])
    assert p.returncode != 0 and '"1/(t-0.5)": value inf at t = 0.5' in p.stderr, p.stderr
    q = run([PY, os.path.join(SCRIPTS, "skfem_solve.py"), str(path), "-o", str(tmp_path / "p.h5"), "-q"])
    lines = [ln for ln in q.stderr.splitlines() if ln.startswith("error:")]
    assert q.returncode == 2 and "Traceback" not in q.stderr and len(lines) == 1, q.stderr[-2000:]
    assert "expression '1/(t-0.5)' has the value inf at (x, y) = (" in lines[0] and "t = 0.5" in lines[0], lines

"""The data of a manufactured case: from its displacement u(x, y, t) (exact sympy), f = -div sigma(u),
sigma(u) n on every Neumann side, u0 = u(., 0), grad u, and every one of them printed in exmex syntax."""
import sympy as sp

from tresca_py.expr import ExprError, lint, symbols
from tresca_py.elastic import lame
from tresca_py.mms.elasticity import body_force, grad_of, side_normal_exact, stress
from tresca_py.mms.exmex import ex

x, y, t = symbols()


class CheckFailed(Exception):
    """A manufactured case fails a check (the message names the case and the check)."""


def require(cond, what):
    if not cond:
        raise CheckFailed(what)

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
    d["str"] = printed(case["name"], sym)
    return d


def printed(name, sym):
    """Every sympy expression of ``sym`` printed in exmex syntax; CheckFailed where the solver's scene lint
    (src/scene/expr/lint.rs) would refuse a string."""
    out = {k: ex(v) for k, v in sym.items()}
    for k, v in out.items():
        try:
            lint(v)
        except ExprError as err:
            raise CheckFailed("%s: %s violates exmex syntax rules: %s" % (name, k, err)) from None
    return out

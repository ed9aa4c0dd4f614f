"""Scene expressions in UFL (sympy -> UFL), the bilinear form a_h and the load and true-error forms of the
dolfinx re-implementations (serial and distributed), with the fixed quadrature rules of the discrete problem."""
from types import SimpleNamespace

import dolfinx_solver  # noqa: F401  (loads libmpi for the wheel; must precede dolfinx)
import ufl
from dolfinx import fem

from tresca_py.errors import InputError
from tresca_py.quadrature import DUNAVANT_REF_W, DUNAVANT_REF_X


def stiffness_forms(scene, msh, V, ft):
    """The terms of a_h on V with the boundary tags ``ft`` (part index + 1): ``a_el`` (elasticity, one-point
    rule: the integrand is constant), ``a_jump`` (the jump stabilisation 2ρμ/h [u]·[v], 2-point Gauss),
    ``a_dir`` (the Dirichlet penalty 2ρμ/h u·v on Γ_D, None without a Dirichlet part), with the test
    function ``v``, the measures ``dS2``, ``ds``, ``h`` = |e|, ``pen`` = 2ρμ/h and the part ``ids`` by kind."""
    ids = {kind: tuple(i + 1 for i, b in enumerate(scene.boundaries) if b.kind == kind)
           for kind in ("dirichlet", "neumann", "contact")}
    lam, mu, rho = scene.lam, scene.mu, scene.rho
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    eps = lambda w: ufl.sym(ufl.grad(w))  # noqa: E731
    sigma = lambda w: lam * ufl.tr(eps(w)) * ufl.Identity(2) + 2 * mu * eps(w)  # noqa: E731
    dx0 = ufl.Measure("dx", domain=msh, metadata={"quadrature_degree": 0})   # integrand is constant
    dS2 = ufl.Measure("dS", domain=msh, metadata={"quadrature_degree": 3})   # 2-point Gauss
    ds = ufl.Measure("ds", domain=msh, subdomain_data=ft)
    h = ufl.FacetArea(msh)
    pen = 2.0 * rho * mu / h
    a_dir = None
    if ids["dirichlet"]:
        a_dir = pen * ufl.inner(u, v) * ds(ids["dirichlet"], metadata={"quadrature_degree": 3})
    return SimpleNamespace(a_el=ufl.inner(sigma(u), eps(v)) * dx0,
                           a_jump=2.0 * rho * mu / h("+") * ufl.inner(ufl.jump(u), ufl.jump(v)) * dS2,
                           a_dir=a_dir, v=v, dS2=dS2, ds=ds, h=h, pen=pen, ids=ids, params=(lam, mu, rho, pen))


def sympy_to_ufl(expr, x, t, key="expression"):
    """Translate a sympy expression in x, y, t into UFL (x: SpatialCoordinate, t: Constant)."""
    import sympy
    rec = lambda e: sympy_to_ufl(e, x, t, key)  # noqa: E731
    if expr.is_Symbol:
        return {"x": x[0], "y": x[1], "t": t}[expr.name]
    if expr.is_number:
        return float(expr)
    if expr.is_Add:
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = out + rec(a)
        return out
    if expr.is_Mul:
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = out * rec(a)
        return out
    if expr.is_Pow:
        b, e = expr.args
        if e == sympy.Rational(1, 2):
            return ufl.sqrt(rec(b))
        return rec(b) ** (int(e) if e.is_Integer else rec(e))
    unary = {sympy.sin: ufl.sin, sympy.cos: ufl.cos, sympy.tan: ufl.tan, sympy.exp: ufl.exp,
             sympy.log: ufl.ln, sympy.Abs: abs, sympy.sign: ufl.sign, sympy.tanh: ufl.tanh,
             sympy.sinh: ufl.sinh, sympy.cosh: ufl.cosh}
    if expr.func in unary:
        return unary[expr.func](rec(expr.args[0]))
    if expr.func == sympy.atan2:
        return ufl.atan2(rec(expr.args[0]), rec(expr.args[1]))
    if isinstance(expr, sympy.Piecewise):
        # e.g. signum (see tresca_py.expr); the last branch must be unconditional
        rel = {sympy.StrictLessThan: ufl.lt, sympy.LessThan: ufl.le, sympy.StrictGreaterThan: ufl.gt,
               sympy.GreaterThan: ufl.ge}
        out = None
        for val, cond in reversed(expr.args):
            if cond is sympy.true:
                out = rec(val)
            elif type(cond) in rel and out is not None:
                out = ufl.conditional(rel[type(cond)](rec(cond.args[0]), rec(cond.args[1])), rec(val), out)
            else:
                raise InputError(f"{key}: piecewise condition {cond} has no UFL equivalent")
        return out
    if expr.func in (sympy.Min, sympy.Max):
        op = ufl.min_value if expr.func == sympy.Min else ufl.max_value
        out = rec(expr.args[0])
        for a in expr.args[1:]:
            out = op(out, rec(a))
        return out
    raise InputError(f"{key}: '{expr.func}' has no UFL equivalent (the dolfinx solver cannot use it)")


def vec_to_ufl(vexpr, x, t):
    return ufl.as_vector([sympy_to_ufl(c.sym, x, t, c.key) for c in vexpr.comps])


def dunavant_dx(msh):
    """The cell measure with the 6-point Dunavant rule (degree 4) of the Rust solver and scikit-fem."""
    return ufl.Measure("dx", domain=msh, metadata={
        "quadrature_rule": "custom", "quadrature_points": DUNAVANT_REF_X.T.copy(),
        "quadrature_weights": DUNAVANT_REF_W.copy()})


def error_forms(scene, uh, t, params, h, dS2, ds, dirichlet, data=False):
    """Compiled forms of the squared true errors of uh against the scene's exact solution: energy (with
    the jump terms on interior edges and on the Dirichlet part `dirichlet`, 2-point Gauss; with boundary
    data, `data`, the jump of the error on Γ_D is uh − u), H1 seminorm and L2, by the Dunavant rule.
    params = (lambda, mu, rho, 2 rho mu / h penalty on Gamma_D)."""
    lam, mu, rho, pen = params
    msh = uh.function_space.mesh
    X, dx4 = ufl.SpatialCoordinate(msh), dunavant_dx(msh)
    ue = vec_to_ufl(scene.exact_u, X, t)
    G = ufl.as_matrix([[sympy_to_ufl(scene.exact_grad[i][j].sym, X, t) for j in range(2)]
                       for i in range(2)]) - ufl.grad(uh)
    Es = ufl.sym(G)
    el = (lam * ufl.tr(Es) ** 2 + 2 * mu * ufl.inner(Es, Es)) * dx4
    # jump part of the energy error as an integral of squares (no cancellation)
    el = el + 2.0 * rho * mu / h("+") * ufl.inner(ufl.jump(uh), ufl.jump(uh)) * dS2
    if dirichlet:
        jd = uh - ue if data else uh
        el = el + pen * ufl.inner(jd, jd) * ds(dirichlet, metadata={"quadrature_degree": 3})
    return [fem.form(el), fem.form(ufl.inner(G, G) * dx4), fem.form(ufl.inner(ue - uh, ue - uh) * dx4)]


def load_form(scene, msh, v, ds, t):
    """The load functional (l(t), v) as a compiled form (None without loads): the body force by the
    6-point Dunavant rule, tractions on Neumann part i (measure ds(i + 1)) and the given surface loads of contact
    parts (issue 40: in addition to the contact reaction) by 3-point Gauss (degree 5)."""
    X = ufl.SpatialCoordinate(msh)
    dx4 = dunavant_dx(msh)
    L = None
    if not scene.f.is_zero:
        L = ufl.inner(vec_to_ufl(scene.f, X, t), v) * dx4
    for i, b in enumerate(scene.boundaries):
        if b.kind in ("neumann", "contact") and b.traction is not None and not b.traction.is_zero:
            term = ufl.inner(vec_to_ufl(b.traction, X, t), v) * ds(i + 1, metadata={"quadrature_degree": 5})
            L = term if L is None else L + term
    return None if L is None else fem.form(L)


def data_forms(scene, msh, v, ds, t, pen, parts):
    """The boundary data's forms on the Dirichlet parts ``parts`` (measure ids) with `u`, by 3-point Gauss
    (degree 5): b_D(t; v) = Σ (2ρμ/h_e) ∫_e u_D·v and c(t) = Σ (2ρμ/h_e) ∫_e |u_D|², ``pen`` = 2ρμ/h_e."""
    X = ufl.SpatialCoordinate(msh)
    b = c = None
    for i in parts:
        ud = vec_to_ufl(scene.boundaries[i - 1].u, X, t)
        dsi = ds(i, metadata={"quadrature_degree": 5})
        b = pen * ufl.inner(ud, v) * dsi if b is None else b + pen * ufl.inner(ud, v) * dsi
        c = pen * ufl.inner(ud, ud) * dsi if c is None else c + pen * ufl.inner(ud, ud) * dsi
    return fem.form(b), fem.form(c)

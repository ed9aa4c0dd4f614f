"""References for the stability cases: conforming P1 on the near-incompressible case (scikit-fem) and the
condition number of the reduced stabilised CR stiffness."""
import os

import numpy as np
import sympy as sp

from tresca_py.expr import symbols

from tresca_py.elastic import lame
from tresca_py.mms.near_incompressible import field

x, y, t = symbols()


def p1_h1_error(nu, n):
    """H1-seminorm error of conforming P1 (ElementVector(ElementTriP1())) on the n x n clamped square."""
    from skfem import Basis, ElementTriP1, ElementVector, Functional, LinearForm, MeshTri, asm, condense, solve
    from skfem.models.elasticity import linear_elasticity
    u = [c.subs(t, 1) for c in field()[0]]                # the case at t = 1
    f = [-(sp.diff(c, x, 2) + sp.diff(c, y, 2)) for c in u]
    fl = [sp.lambdify((x, y), c, "numpy") for c in f]
    gl = [[sp.lambdify((x, y), sp.diff(c, v), "numpy") for v in (x, y)] for c in u]
    lam, mu = lame(2 * (1 + nu), nu)
    g = np.linspace(0, 1, n + 1)
    m = MeshTri.init_tensor(g, g)
    basis = Basis(m, ElementVector(ElementTriP1()), intorder=4)
    K = asm(linear_elasticity(lam, mu), basis)

    @LinearForm
    def load(v, w):
        X, Y = w.x
        return fl[0](X, Y) * v.value[0] + fl[1](X, Y) * v.value[1]

    b = asm(load, basis)
    uh = solve(*condense(K, b, D=basis.get_dofs()))
    uhi = basis.interpolate(uh)

    @Functional
    def err(w):
        X, Y = w.x
        G = w["uh"].grad
        return sum((G[i][j] - gl[i][j](X, Y)) ** 2 for i in range(2) for j in range(2))

    return float(np.sqrt(err.assemble(basis, uh=uhi)))


def cond_K(st, scene_path, refine):
    """Condition number of the reduced stabilised CR stiffness (scikit-fem assembly of the same a_h)."""
    from tresca_py import cli as ts
    from tresca_py.skfem_cr.assemble import SkfemProblem
    from tresca_py.skfem_cr.cr import Discretisation
    args = ts.cli("cond", [scene_path, "-o", os.path.join(st.tmp, "c.h5"), "--refine", str(refine), "-q"])
    scene, disc, _ = ts.open_scene(args, Discretisation)
    K = SkfemProblem(disc).K
    free = np.ones(len(disc.edges), bool)
    free[disc.dirichlet] = False
    idx = np.flatnonzero(np.repeat(free, 2))
    ev = np.linalg.eigvalsh(K.toarray()[np.ix_(idx, idx)])
    return float(ev[-1] / ev[0]) if ev[0] > 0 else float("inf"), float(ev[0]), float(ev[-1])

"""Plane-strain elasticity of a manufactured displacement (grad u, sigma(u), f = -div sigma, sigma n), the
geometry of the structured quadrilateral's sides, and the local construction of fields on a contact side.
"""
import numpy as np
import sympy as sp

from tresca_py.expr import symbols

x, y, t = symbols()

def grad_of(u):
    """[[du1/dx, du1/dy], [du2/dx, du2/dy]]."""
    return sp.Matrix([[sp.diff(u[0], x), sp.diff(u[0], y)], [sp.diff(u[1], x), sp.diff(u[1], y)]])


def stress(G, lam_, mu):
    eps = (G + G.T) / 2
    return lam_ * eps.trace() * sp.eye(2) + 2 * mu * eps


def body_force(S):
    """f = -div sigma (row divergence)."""
    return [-(sp.diff(S[0, 0], x) + sp.diff(S[0, 1], y)), -(sp.diff(S[1, 0], x) + sp.diff(S[1, 1], y))]


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

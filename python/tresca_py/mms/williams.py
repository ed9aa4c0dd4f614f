"""The Williams eigenfunction of the L-shape's re-entrant corner (issue 33, mms_lshape).

Plane-strain elasticity in a wedge of half-angle ω (faces θ = ±ω, θ from the bisector) has the traction-free
solutions r^λ Φ(θ). The symmetric mode (Williams 1952; Szabó & Babuška, Finite Element Analysis, 1991, §
"the L-shaped domain", in its Cartesian form) is, with κ = 3 − 4ν,

    u_ξ = r^λ [(κ − Q(λ+1)) cos λθ − λ cos (λ−2)θ],   u_η = r^λ [(κ + Q(λ+1)) sin λθ + λ sin (λ−2)θ],
    Q = −cos((λ−1)ω) / cos((λ+1)ω),   λ sin 2ω + sin 2λω = 0,

(ξ along the bisector, η across it, the factor 1/(2μ) dropped). For ω = 3π/4 (interior angle 3π/2) the
smallest root is λ = 0.5444837…, so ∇u ~ r^(λ−1) and u ∈ H^(1+λ−ε) only. The equations hold for any λ and Q
(div σ(u) = 0 identically); the faces are free of traction only at the root with that Q
(:func:`polar_checks` shows both).

On the L-shape (0,2)² ∖ [1,2]² the corner is (1, 1), the body's bisector points to (0, 0), and
ξ = −(X+Y)/√2, η = (X−Y)/√2 (X = x−1, Y = y−1): θ = atan2(x − y, 2 − x − y) puts atan2's branch cut on the
ray θ = ±π, the diagonal of the excluded square. The global field is √2·(u_ξ e_ξ + u_η e_η).
λ and Q enter the expressions as the symbols :data:`LAM` and :data:`Q`, printed as their double values.
"""
import mpmath as mp
import sympy as sp

from tresca_py.expr import symbols
from tresca_py.elastic import lame

x, y, t = symbols()
LAM, Q = sp.symbols("lamW qW", positive=True)
OMEGA = 3 * sp.pi / 4


def exponent(dps=30):
    """The smallest positive root λ of λ sin 2ω + sin 2λω = 0 for ω = 3π/4, a sympy Float of ``dps`` digits."""
    with mp.workdps(dps + 5):
        om = 3 * mp.pi / 4
        root = mp.findroot(lambda lam: lam * mp.sin(2 * om) + mp.sin(2 * lam * om), mp.mpf("0.54"))
        return sp.Float(mp.nstr(root, dps + 5), dps)


def q_of(lam):
    """Q of the symmetric mode for the exponent ``lam`` (a number or a sympy expression)."""
    return -sp.cos((lam - 1) * OMEGA) / sp.cos((lam + 1) * OMEGA)


def values():
    """{LAM: λ, Q: Q(λ)} as sympy Floats of the doubles the scene prints."""
    lam = exponent()
    return {LAM: sp.Float(float(lam)), Q: sp.Float(float(q_of(lam).evalf(30)))}


def local_mode(r, th, kappa):
    """(u_ξ, u_η) of the symmetric mode in polar coordinates (r, θ) about the corner."""
    c1, c2 = kappa - Q * (LAM + 1), kappa + Q * (LAM + 1)
    return (r ** LAM * (c1 * sp.cos(LAM * th) - LAM * sp.cos((LAM - 2) * th)),
            r ** LAM * (c2 * sp.sin(LAM * th) + LAM * sp.sin((LAM - 2) * th)))


def field(nu):
    """The mode in global (x, y) on the L-shape: [w1, w2] (sympy, in LAM and Q)."""
    r = sp.sqrt((x - 1) ** 2 + (y - 1) ** 2)
    th = sp.atan2(x - y, 2 - x - y)
    u_xi, u_eta = local_mode(r, th, 3 - 4 * nu)
    return [u_eta - u_xi, -u_xi - u_eta]


def polar_checks(nu):
    """Symbolic div σ(u) in the wedge's frame (zero for all λ, Q: returned simplified) and the traction
    σ(u)n on the faces θ = ±ω as functions of (λ, Q, r) (zero at the root): (div, [face tractions])."""
    r, th = sp.symbols("r theta", positive=True)
    lam_, mu = lame(1, nu)
    u_xi, u_eta = local_mode(r, th, 3 - 4 * nu)

    def dxi(f):
        return sp.cos(th) * sp.diff(f, r) - sp.sin(th) / r * sp.diff(f, th)

    def deta(f):
        return sp.sin(th) * sp.diff(f, r) + sp.cos(th) / r * sp.diff(f, th)

    e11, e22, e12 = dxi(u_xi), deta(u_eta), (deta(u_xi) + dxi(u_eta)) / 2
    s11 = lam_ * (e11 + e22) + 2 * mu * e11
    s22 = lam_ * (e11 + e22) + 2 * mu * e22
    s12 = 2 * mu * e12
    div = [sp.simplify(sp.expand_trig(sp.expand(dxi(s11) + deta(s12)))),
           sp.simplify(sp.expand_trig(sp.expand(dxi(s12) + deta(s22))))]
    faces = []
    for th_f in (OMEGA, -OMEGA):
        n = (-sp.sin(th_f), sp.cos(th_f))
        sub = {th: th_f}
        faces += [(s11 * n[0] + s12 * n[1]).subs(sub), (s12 * n[0] + s22 * n[1]).subs(sub)]
    return div, faces

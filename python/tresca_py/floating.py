"""A floating body (no Dirichlet part, held only by contact and symmetry parts; issue 40) in the re-implementations:
the geometry of its rigid motions and the outer iteration on their equilibrium, which both Python solvers use
around their own factorisation and their own bound-constrained solver (docs/model.md "Floating bodies"; the
Rust solver's src/friction/floating.rs).

A rigid motion is linear, so CR interpolates it exactly and a_h vanishes on it: with normal unknowns on every Γ_C
edge (the only floating scenes the re-implementations take) the reduced stiffness K_r has the three motions R_r
(translations x, y and the rotation about the centroid, scaled by the body's size) as its kernel. With k pinned
unknowns p (R_r[p] nonsingular), K_# is K_r with those rows and columns replaced by their diagonal and
K⁺ b = K_#⁻¹ b with b_p and the result's p entries zeroed is a generalized inverse. Then u = K⁺(l − Bλ) + R_r α
and a step solves the friction problem with Δ = d − Cλ + Gα and the equilibrium Gᵀλ = e (G = BᵀR_r, e = R_rᵀl),
by the method of multipliers (Hestenes–Powell): the inner bound-constrained problem with C + ρGGᵀ and
d + G(α + ρe), exactly, then α ← α + ρ(e − Gᵀλ), until max|e − Gᵀλ| ≤ EQ_TOL of the force scale.
"""
import numpy as np
import scipy.linalg as la
import scipy.sparse as sp

#: ρ = AUGMENT · max C_ee with G orthonormal (the Rust solver's choice): each outer iteration contracts the
#: equality residual by about κ-independent orders of magnitude
AUGMENT = 1e4
#: the equality residual every step reaches, relative to the force scale (a few hundred ulps)
EQ_TOL = 1e-14
MAX_OUTER = 200


def rigid_motions(points, midpoints):
    """(n_edges, 2, 3): the three rigid motions at the edge midpoints (x, y, rotation about the vertex centroid
    scaled by the largest distance to it)."""
    c = points.mean(axis=0)
    size = max(float(np.max(np.hypot(*(points - c).T))), np.finfo(float).tiny)
    m = np.zeros((len(midpoints), 2, 3))
    m[:, 0, 0] = m[:, 1, 1] = 1.0
    m[:, 0, 2] = -(midpoints[:, 1] - c[1]) / size
    m[:, 1, 2] = (midpoints[:, 0] - c[0]) / size
    return m


def kernel(P, points, midpoints, ic):
    """(R_r, pinned): the motions in the reduced unknowns u = P r (P has orthonormal columns), scaled so that
    G = R_r[ic] has orthonormal columns, and k unknowns off Γ_C where R_r is nonsingular (QR with column pivoting;
    off Γ_C so that C = BᵀK⁺B keeps full rank)."""
    R = P.T @ rigid_motions(points, midpoints).reshape(-1, 3)
    _, t = np.linalg.qr(R[ic])
    R = la.solve_triangular(t, R.T, trans="T").T                   # R T⁻¹: G = R[ic] orthonormal
    off = np.setdiff1d(np.arange(R.shape[0]), ic)
    _, _, piv = la.qr(R[off].T, pivoting=True, mode="economic")
    return R, np.sort(off[piv[:R.shape[1]]])


def pin(K, pinned):
    """K_#: ``K`` (scipy sparse) with the rows and columns of ``pinned`` zero except their diagonal."""
    keep = np.ones(K.shape[0])
    keep[pinned] = 0.0
    D = sp.diags(keep)
    return (D @ K @ D + sp.diags(K.diagonal() * (1.0 - keep))).tocsc()


def multipliers(inner, C, d, G, e, lam0, alpha0):
    """Method of multipliers (module docstring) with ``inner(C_rho, d_rho, lam0) -> (lam, iterations)`` exact;
    returns (λ, α, iterations, equality residual relative to the force scale max(|e|, |λ|)). RuntimeError when the
    residual stops shrinking (the loads are not balanced by forces within the bounds)."""
    rho = AUGMENT * max(float(np.max(np.diag(C))), 1e-300)
    C_rho = C + rho * G @ G.T
    lam, alpha, its, best, stall = lam0, alpha0.copy(), 0, np.inf, 0
    for _ in range(MAX_OUTER):
        lam, k = inner(C_rho, d + G @ (alpha + rho * e), lam)
        its += k
        res = e - G.T @ lam
        alpha = alpha + rho * res
        scale = max(float(np.max(np.abs(e), initial=0.0)), float(np.max(np.abs(lam), initial=0.0)), 1e-300)
        r = float(np.max(np.abs(res), initial=0.0)) / scale
        if r <= EQ_TOL:
            return lam, alpha, its, r
        stall = stall + 1 if r > 0.5 * best else 0
        best = min(best, r)
        if stall >= 8:
            break
    raise RuntimeError(f"floating body: the equilibrium of the rigid motions is not reached (residual {r:.3e} of "
                       f"the force scale after {its} iterations): the loads are not balanced")

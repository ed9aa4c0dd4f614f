"""The scikit-fem re-implementation of tresca-cr's discrete problem (independent of the Rust crate).

Modules: ``cr`` (edges, boundary parts, contact data, CR interpolant, reduction), ``assemble`` (a_h, its
jump part, loads and true errors with scikit-fem), ``lifting`` (boundary data u_D and g_n: u = w + u_L),
``friction`` (the exact per-step friction solver), ``unilateral`` (the step with normal unknowns: Signorini,
Coulomb), ``stepping`` (backward Euler and the results file), ``main``
(the command line, scripts/skfem_solve.py). It imports nothing from the dolfinx re-implementation.

The mathematics
---------------
Unknowns are CR vector fields, one 2-vector per edge midpoint m_e, stored in the *canonical*
ordering ``2*e + c`` (edge e of ``Discretisation.edges``, component c). Dirichlet edges carry zero.
A contact edge e with outward normal n_e and tangent tau_e = (-n_y, n_x) carries u(m_e) = s_e tau_e.
(With boundary data these describe w; the displacement written is u = w + u_L, ``lifting``.)
The reduced space is parametrised by ``u = P r`` where r holds two numbers per free edge and one
number s_e per contact edge (listed last).  A framework script assembles, in the canonical ordering,

    K = a_h   (elasticity + jump stabilisation (2 rho mu / h_e) int_e [u].[v], 2-point Gauss)
    J = the jump part of a_h alone (for the energy error)
    l(t) = int f(t).v (6-point Dunavant) + int_{Gamma_N} g(t).v (3-point Gauss).

Backward Euler step n minimises  1/2 a_h(v,v) - (l^n, v) + sum_e w_e |s_e(v) - s_e^{n-1}|  with
w_e = |e| * mean_e(g_a).  Writing K_r = P^T K P, the optimality system is

    K_r r = P^T l - B mu,   mu_e in w_e * d|.|(s_e - s_e^{n-1}),   s = B^T r,

B selecting the contact unknowns.  Eliminating r (Z = K_r^{-1} B, C = B^T Z, s_free = B^T K_r^{-1} P^T l)
gives s = s_free - C mu and the box-constrained dual QP

    min_mu  1/2 mu^T C mu - mu^T d,   |mu_e| <= w_e,   d = s_free - s^{n-1},

solved exactly (to rounding) by a primal active-set method (finite, warm-started from the previous
step). Then r = K_r^{-1} P^T l - Z mu.  Tangential traction sigma_t,e = -mu_e / |e|; an edge slips
(state 1) when |mu_e| >= w_e (1 - 1e-9) and |ds_e| > 1e-9 * max(|ds|_inf, |d|_inf), ds = d - C mu (the
convention of the Rust solver, see ``classify``).
The initial value u^0 = I_CR u0 is the edge mean of u0 by 3-point Gauss (tau component on Gamma_C).
"""

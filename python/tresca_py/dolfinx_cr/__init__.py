"""The DOLFINx 0.11 re-implementation of tresca-cr's discrete problem.

Independent of the Rust crate and of the scikit-fem re-implementation (it imports nothing from it). Modules:
``edges`` (its own edge table, boundary parts, Γ_C data, CR interpolant, lifting of the boundary data and the
reduction u = P r), ``forms`` (sympy -> UFL, the load, data and error forms), ``assemble`` (distributed assembly
gathered to rank 0), ``friction`` (K_r by MUMPS Cholesky, each step's dual friction problem by PETSc TAO TRON),
``stepping`` (backward Euler with the boundary data, the stick/slip rule, the results file), ``unilateral``
(normal unknowns: unilateral Tresca by TAO with bounds and an active-set polish, and floating bodies), ``main``
(scripts/dolfinx_solve.py), ``distributed`` (scripts/dolfinx_distributed.py).

What it shares with the scikit-fem re-implementation is the scene format and its reading
(``tresca_py.scene``/``expr``/``scene_data``), the meshes (``tresca_py.mesh``), the quadrature constants, the
results schema (``tresca_py.results``) and the command line (``tresca_py.cli``); verification/README.md lists it.
It shares nothing with the Rust solver but the scene format.  The discrete problem (README, Problem 2 of
Porwal & Wadhawan), written in UFL with the vector CR element ("CR", 1, (2,)):

    a_h(u, v) = int sigma(u):eps(v) dx
              + int_{dS} (2 rho mu / h_e) jump(u).jump(v) dS + int_{Gamma_D} (2 rho mu / h_e) u.v ds
                (both facet terms with the 2-point Gauss rule, h_e = FacetArea)
    (l^n, v)  = int f(t_n).v dx  (6-point Dunavant, custom rule) + int_{Gamma_N} g(t_n).v ds (3-point Gauss)
    u^n = argmin_v 1/2 a_h(v,v) - (l^n, v) + sum_{e in Gamma_C} |e| gbar_e |v_tau(m_e) - u^{n-1}_tau(m_e)|

Scene expressions are translated sympy -> UFL (x = SpatialCoordinate, t = a fem.Constant), so loads
are evaluated exactly at the quadrature points.  Parallel layout: matrices and load vectors are
assembled distributed (ghost contributions included), gathered to rank 0 in the canonical edge
ordering (edges matched by midpoint coordinates), and the small per-step friction problem is solved
on rank 0 (``friction``); true errors are assembled distributed again.
"""

"""The requirements on the discretisation's accuracy: convergence orders in h and k, and the same discrete
solution from other solvers of the same scheme (scikit-fem, dolfinx) on the unilateral and Hertz cases.

Rows of :data:`tresca_py.verify.requirements.REQUIREMENTS` (in the order of verification/README.md's table).
"""
from tresca_py.verify.requirement import Requirement

ORDERS = (
    Requirement(
        'E1-rect',
        'converge with order 1 ± 0.1 (energy) and 2 ± 0.15 (L²) on a smooth manufactured elasticity problem on a '
        'rectangle, 5 levels',
        'tresca-cr study verification/cases/elastic_rect.toml --levels 2:1,3:1,4:1,5:1,6:1',
        'reference/h_elastic_rect.md',
    ),
    Requirement(
        'E2-rotated',
        '… the same on a rotated square',
        'tresca-cr study verification/cases/elastic_rotated.toml --levels 2:1,…,6:1',
        'reference/h_elastic_rotated.md',
    ),
    Requirement(
        'C1-front',
        'converge with order 1 ± 0.1 in the energy norm on a Tresca problem whose stick–slip front moves in time '
        '(`mms_front`, 5 levels, N = 64)',
        'tresca-cr study verification/cases/mms_front.toml --levels 0:64,…,4:64',
        'reference/h_mms_front.md',
    ),
    Requirement(
        'C2-rotated',
        '… on a contact edge that is not axis-aligned (`mms_rotated`)',
        'tresca-cr study verification/cases/mms_rotated.toml --levels 0:16,…,4:16',
        'reference/h_mms_rotated.md',
    ),
    Requirement(
        'C3-data-front',
        'converge with order 1 ± 0.1 in the energy norm when Dirichlet data u_D ≠ 0 and an imposed normal displacement '
        'g_n ≠ 0 are given and a stick–slip front moves (`mms_data_front`, 5 levels, N = 64)',
        'tresca-cr study verification/cases/mms_data_front.toml --levels 0:64,…,4:64',
        'reference/h_mms_data_front.md',
    ),
    Requirement(
        'C4-data-cep',
        'converge with order 1 ± 0.1 (energy) and 2 ± 0.15 (L²), free of locking, on the near-incompressible Tresca '
        'solution of Chouly, Ern & Pignet (λ = 2·10⁴, μ = 2, Dirichlet data on three sides, `mms_data_cep`, 6 levels)',
        'tresca-cr study verification/cases/mms_data_cep.toml --levels 0:1,…,5:1',
        'reference/h_mms_data_cep.md',
    ),
    Requirement(
        'K1-mms_stop',
        'converge with order 1 ± 0.1 in k when slip stops abruptly inside a step (`mms_stop`, t* = 1/3, N = 4^j; time '
        'error against the N = 4096 solution on the same mesh)',
        'tresca-cr study verification/cases/mms_stop.toml --levels 3:4,3:16,3:64,3:256 --reference 3:4096',
        'reference/k_study_mms_stop.md',
    ),
    Requirement(
        'K3-data-stop',
        '… the same in k with Dirichlet data and an imposed normal displacement (`mms_data_stop`, N = 4^j against N = '
        '4096 on the same mesh)',
        'tresca-cr study verification/cases/mms_data_stop.toml --levels 3:4,3:16,3:64,3:256 --reference 3:4096',
        'reference/k_study_mms_data_stop.md',
    ),
    Requirement(
        'K2-stick-to-slip',
        'give errors independent of k (relative spread ≤ 1e-8) while points only pass from stick to slip: backward '
        'Euler is exact at the nodes (a finding, `mms_stick_to_slip`)',
        'tresca-cr study verification/cases/mms_stick_to_slip.toml --levels 3:2,3:8,3:32,3:128',
        'reference/be_exact_stick_to_slip.md',
    ),
    Requirement(
        'J1-joint',
        'converge with order 1 ± 0.1 in h under joint refinement h → h/2, k → k/4 (`mms_stop`)',
        'tresca-cr study verification/cases/mms_stop.toml --levels 0:1,1:4,2:16,3:64,4:256',
        'reference/joint_mms_stop.md',
    ),
    Requirement(
        'U1-skfem-signorini',
        'converge with order 1 ± 0.1 (energy) and 2 ± 0.15 (L²) on a manufactured Signorini–Tresca solution whose '
        'contact/separation and stick/slip points move (`mms_signorini_moving`, scikit-fem solver, 5 levels, N = 8; '
        'every step to a natural residual ≤ 1e-12)',
        '.venv/bin/python scripts/skfem_solve.py verification/cases/mms_signorini_moving.toml --refine k --steps 8',
        'reference/h_skfem_mms_signorini_moving.md',
    ),
    Requirement(
        'U2-skfem-signorini-incompressible',
        '… the same, free of locking, near-incompressible (λ/μ = 10⁴, `mms_signorini_incompressible`, refine 1..5: '
        'its L² error is pre-asymptotic at refine 0)',
        '.venv/bin/python scripts/skfem_solve.py verification/cases/mms_signorini_incompressible.toml --refine k '
        '--steps 8',
        'reference/h_skfem_mms_signorini_incompressible.md',
    ),
    Requirement(
        'U3-skfem-coulomb',
        '… the same with Coulomb friction whose threshold is F times the exact pressure (`mms_signorini_coulomb`)',
        '.venv/bin/python scripts/skfem_solve.py verification/cases/mms_signorini_coulomb.toml --refine k --steps 8',
        'reference/h_skfem_mms_signorini_coulomb.md',
    ),
    Requirement(
        'U4-skfem-signorini-k',
        'converge with order 1 ± 0.1 in k when the slip stops abruptly on a unilateral contact part (time error at '
        'refine 2 against N = 4096 on the same mesh, N = 4, 16, 64, 256, `mms_signorini_stop`, scikit-fem)',
        '.venv/bin/python scripts/skfem_solve.py verification/cases/mms_signorini_stop.toml --refine 2 --steps N',
        'reference/k_skfem_mms_signorini_stop.md',
    ),
    Requirement(
        'HZ1-hertz-discretisation',
        'converge on the Hertz line contact (plane-strain cylinder on a rigid plane, frictionless unilateral, '
        'symmetry axis, floating under a load P, a/R = 0.1 and 0.05, 5 graded mesh levels): the displacement of '
        'the load and the moment half-width with fitted order '
        '2 ± 0.5 and last successive order ≥ 1, the peak pressure changing ≤ 1/4 of the model bound at the finest',
        '.venv/bin/python verification/run_all.py --only hertz',
        'reference/hertz.md',
    ),
    Requirement(
        'HZ2-hertz-formulas',
        "agree with Hertz's a = √(4PR/(πE*)) and p₀ = 2P/(πa) within κ a/(2R), κ = (1 − 2ν)/(1 − ν) (the "
        "linearised normal's first-order model error), with the profile p₀√(1 − x²/a²) within κ a/R in L², and "
        "balance P by the contact pressure to 1e-9",
        '.venv/bin/python verification/run_all.py --only hertz',
        'reference/hertz.md',
    ),
    Requirement(
        'HZ3-hertz-model-order',
        'deviate from Hertz (a, p₀) by a model error that shrinks with a/R at order 1 ± 0.3 '
        '(a/R = 0.1 → 0.05) and falls below half at ν = 0.49, where its first-order term nearly vanishes',
        '.venv/bin/python verification/run_all.py --only hertz',
        'reference/hertz.md',
    ),
    Requirement(
        'HZ4-hertz-polygon',
        "keep the polygonal disc's own error (circle's gap instead of the polygon's) ≤ h²/(8a²) and ≤ 1/4 of the "
        "discretisation error of the half-width at every level",
        '.venv/bin/python verification/run_all.py --only hertz',
        'reference/hertz.md',
    ),
    Requirement(
        'U5-rust-signorini',
        'converge with order 1 ± 0.1 (energy) and 2 ± 0.15 (L²) on `mms_signorini_moving` itself (tresca-cr, the '
        'levels and N of U1: true errors against the exact solution of tresca_py.mms)',
        'tresca-cr study verification/cases/mms_signorini_moving.toml --levels 0:8,…,4:8',
        'reference/h_rust_mms_signorini_moving.md',
    ),
    Requirement(
        'U6-rust-signorini-incompressible',
        '… the same near-incompressible, free of locking (`mms_signorini_incompressible`, refine 1..5, tresca-cr)',
        'tresca-cr study verification/cases/mms_signorini_incompressible.toml --levels 1:8,…,5:8',
        'reference/h_rust_mms_signorini_incompressible.md',
    ),
    Requirement(
        'U7-rust-coulomb',
        '… the same with Coulomb friction (`mms_signorini_coulomb`, tresca-cr\'s semismooth Newton method): it '
        'converges to the manufactured solution with the same orders, not merely to some fixed point',
        'tresca-cr study verification/cases/mms_signorini_coulomb.toml --levels 0:8,…,4:8',
        'reference/h_rust_mms_signorini_coulomb.md',
    ),
    Requirement(
        'U8-rust-signorini-k',
        'converge with order 1 ± 0.1 in k when the slip stops abruptly on a unilateral contact part (tresca-cr, '
        '`mms_signorini_stop`, N = 4^j against N = 4096 on the same mesh at refine 3)',
        'tresca-cr study verification/cases/mms_signorini_stop.toml --levels 3:4,3:16,3:64,3:256 --reference 3:4096',
        'reference/k_study_mms_signorini_stop.md',
    ),
    Requirement(
        'U9-same-scheme…',
        'solve the discrete unilateral problem as the same-scheme re-implementations do: tresca-cr, scikit-fem '
        '(exact active set) and, for unilateral Tresca, dolfinx (PETSc TAO, bound-constrained) agree pairwise in '
        'u, energies, tractions, pressures and true errors to ≤ 1e-8 (≤ κ(K_r)·κ(C)·u where rounding alone exceeds '
        'it: the near-incompressible scene) with 0 differing stick/slip/separated flags, on the 4 manufactured '
        'Signorini scenes and a floating block (no Dirichlet part) at refine 2',
        'verification/run_all.py --only same_scheme',
        None,
        pattern='U9-same-scheme-.+',
    ),
)

"""The requirements on what surrounds the solver: its files and their clients, interrupted runs, the
cross-checks against independent solvers, the distributed solver, the planner, stability, the study-sized
tests, the fuzz corpus, external codes and the energy audits.

Rows of :data:`tresca_py.verify.requirements.REQUIREMENTS` (in the order of verification/README.md's table).
"""
from tresca_py.verify.requirement import Requirement

TOOLS = (
    Requirement(
        'O1-clients',
        "write results that VTK's `vtkHDFReader`, meshio (XDMF) and h5py open, with the solver's values",
        'scripts/check_results.py out/verify_ex51.h5',
        None,
    ),
    Requirement(
        'O2-interrupted',
        'write files that open in the same three clients for a killed (SIGKILL mid-run), a stopped (solver failure) '
        'and a resumed run, each showing exactly its committed steps',
        'verification/interrupted_runs.py',
        None,
    ),
    Requirement(
        'V1-paraview',
        "be seen in ParaView as users meet it: Debian 12's ParaView 5.11 (`make paraview`; pvpython on a virtual X "
        "server) opens the files of a finished, a killed (SIGKILL) and a resumed run with `XDMFReader`, `Xdmf3ReaderS` "
        "and `Xdmf3ReaderT` as a body block and a contact-line block showing exactly the committed frames, with von "
        "Mises, displacement, slip and stick/slip equal to `/tresca` at two times (≤ 2e-5 relative, f32), and "
        "`scripts/paraview_view.py` renders a PNG whose pixels show a coloured body and the red/blue contact line "
        "(`make test` renders a finished run's PNG, skipped with a message where pvpython is absent)",
        'verification/paraview_check.py',
        'out/paraview/*.png',
    ),
    Requirement(
        'X…',
        'agree with the independent scikit-fem and dolfinx solutions of the same discrete problem to ≤ 1e-8 on every '
        'case at two levels (DOF vectors, energies, stick/slip sets, true errors), and dolfinx under `mpirun -n 2` '
        'with serial',
        'verification/cross_check.py',
        'reference/cross_check.md',
        pattern='X-.+',
    ),
    Requirement(
        'D1-distributed-agree',
        'run distributed (scripts/dolfinx_distributed.py: mesh, a_h, factor and solves spread over the ranks, only the '
        'contact unknowns gathered) and agree with the Rust solver under `mpirun -n 1`, `-n 2` and `-n 3` on every '
        'cross-check scene at its quick level (the boundary-data scenes `mms_data_*` among them) to ≤ 1e-8 (DOF '
        'vectors, energies, σ_τ, true errors), identical stick/slip sets (about 8 min)',
        'verification/distributed.py',
        'reference/distributed.md',
    ),
    Requirement(
        'D2-distributed-memory',
        'spread its memory: on Example 5.1 at refine 8 (1,574,912 unknowns) the peak RSS of the largest rank at `-n 2` '
        'is ≤ 0.6 × the `-n 1` peak (per rank, `/usr/bin/time -f "RSS %M"`), the two runs agreeing to 1e-8; ~5 min, in '
        'the full `make verify` only (`--quick` reports the last measurement, `reference/distributed_memory.json`)',
        'verification/distributed.py --memory',
        'reference/distributed.md',
    ),
    Requirement(
        "PL1, PL2, PL5-<case>",
        "plan the cheapest run for a target accuracy (`tresca-cr plan --run`, the route it recommends: uniform or "
        "adaptive) on every manufactured case with an exact solution: over nine targets a quarter decade apart "
        "spanning two decades, the plan meets the target in truth (true error ≤ target) for every target (PL1, "
        "issue 42: 0 misses), never misses by more than 25 % (PL2), and costs at most 2× the cheapest configuration "
        "of a brute-force grid that meets the target with a 10 % margin (error ≤ 0.9 target), in work units "
        "n^1.5 + N·n·ln n (PL5; CPU times are reported by "
        "`make bench`, `verification/planner.py --costs`, no pass/fail)",
        "verification/planner.py --run",
        "reference/planner.md",
        pattern=r"PL[125]-.+",
    ),
    Requirement(
        'S1…S13',
        'behave as stated at the extremes: locking-free for ν → ½ (conforming P1 locks), exact 1/E scaling, g_a → 0 / '
        '∞ limits, k from 1e-6 to 1, ρ from 1e-4 to 1e4 (ρ → 0 refused), thin and stretched meshes, singular set-ups '
        'refused, no NaN/Inf in any results file',
        'verification/stability.py',
        'reference/stability.md',
        pattern='S\\d+-.+',
    ),
    Requirement(
        'T1-study-tests',
        'pass the study-sized tests that `make test` leaves to `make verify`: the Rust tests marked '
        '`#[ignore = "study-sized …"]` (`cargo test --release --locked --test NAME -- --ignored`) and the Python '
        'tests marked `study` (`pytest -m study`)',
        'verification/run_all.py --only tests',
        None,
    ),
    Requirement(
        'F1-fuzz',
        'not panic on 20 000 fuzzed inputs each for the scene parser (+ set-up and run), expressions and the Gmsh '
        'reader',
        'TRESCA_FUZZ_CASES=20000 cargo test --release --test fuzz -- --nocapture',
        'reference/fuzz.md',
    ),
    Requirement(
        'XA…',
        'reach the same continuous solution as established external codes: on six scenes (Example 5.1, `mms_front`, '
        'the near-incompressible Chouly–Ern–Pignet case, an imposed normal displacement, `mms_rotated`, the '
        'Chouly–Ern–Pignet solution at λ = 3 on a Gmsh pentagon) and four unilateral ones (the manufactured '
        'Signorini–Tresca and Signorini–Coulomb cases, a Coulomb block, Hertz on its own mesh levels) the Richardson '
        'limits of GetFEM P1/P2/Taylor–Hood, an independent scikit-fem P2 Nitsche solver and tresca-cr (‖u‖_H1, '
        '½a(u,u), u·τ at three points, ∫σ_τ, stick-zone ends, max slip; on unilateral scenes also ∫p and max p; on '
        'Hertz ‖u‖_H1, ½a(u,u), ∫p, max p and the half-width 2√(∫p x²/∫p)) agree pairwise within the sum of their '
        'GCI bands',
        'verification/external/run.py',
        'reference/external.md',
        pattern='XA-.+',
    ),
    Requirement(
        'XO…',
        'see each external code converge at its theoretical order where the solution is exact: true H1 errors of P1/CR '
        'at order 1 and P2/Taylor–Hood at order 2 ± 0.15 (fit over the finest four of five levels and the last two '
        'successive orders; locking displacement-only codes on the near-incompressible scene are stated as a finding, '
        'verification/external/README.md)',
        'verification/external/run.py',
        'reference/external.md',
        pattern='XO-.+',
    ),
    Requirement(
        'EB1…',
        'balance the energy of every step, a_h(uⁿ,δuⁿ) + j_h(δuⁿ) = (lⁿ,δuⁿ) + W_Γⁿ (the reactions\' work on imposed '
        'data), to 1e-9 of the largest work of a step plus the rounding allowance of `tresca_py.audit.rounding` (γ_N '
        '(λ+2μ)/μ for the solve of N unknowns, 4ε max|u| ∫g_a for the friction term), with non-negative dissipations, '
        'in every results file that tresca-cr writes during `make verify`: after each study the harness audits the '
        'files it wrote (`tresca_py.audit`, as `scripts/check_results.py`), one result `EB1-<study>` listing every '
        'file with its relative residual; the study `audit` runs every scene of verification/cases/ and '
        'verification/external/scenes/ once with a results file (the `tresca-cr study` cases keep none)',
        'verification/run_all.py (after each study; tresca_py/verify/audits.py)',
        None,
        pattern='EB1-.+',
    ),
)

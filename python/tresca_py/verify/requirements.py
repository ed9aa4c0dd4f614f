"""The requirements of `make verify`, declared once: id, statement, command and reference file.

``verification/README.md``'s table is generated from this list (:mod:`tresca_py.verify.readme`, run by
``make reference``; a pytest test checks the README is current), and the harness
(:mod:`tresca_py.verify.harness`) takes every recorded result's default statement, command and reference
from here and refuses an id that is not declared.

A requirement is one row: ``id``; ``statement``, completing "The solver shall …"; ``command``, the command
that checks it (a shell line, or prose such as "as P2"); ``reference``, the file it writes (``None`` when
its evidence is the command's output). Most requirements record results under their own id or ``id-…``
(``E1-rect-energy``); a family (one row for the cross-check's ``X-<case>-r<k>``) gives a ``pattern``, a
regular expression a recorded id must match in full.
"""
import re
from dataclasses import dataclass
from typing import Optional


@dataclass(frozen=True)
class Requirement:
    id: str
    statement: str
    command: str
    reference: Optional[str]
    pattern: Optional[str] = None

    @property
    def sentence(self):
        """The statement as a sentence: "The solver shall …"."""
        return f"The solver shall {self.statement}"

    def matches(self, rid):
        """True when a recorded result id ``rid`` belongs to this requirement."""
        pattern = self.pattern or re.escape(self.id) + r"(-.+)?"
        return re.fullmatch(pattern, rid) is not None


REQUIREMENTS = (
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
    Requirement(
        'P1-paper-orders',
        "rest on the paper's Table 5.1 as printed (a data check): its orders recomputed from its errors are 0.8577, "
        "0.9671, 0.9015, 0.866",
        'verification/run_all.py --only paper',
        'reference/paper_tables.md',
    ),
    Requirement(
        'P2-paper-runs',
        "run Example 5.1 on the paper's meshes and steps (Tables 5.1, 5.2) with every step converged, consecutive and "
        "true errors decreasing",
        'tresca-cr study verification/cases/paper_example_5_1.toml --levels 0:40,…,4:640 --reference 7:5120',
        'reference/paper_tables.md',
    ),
    Requirement(
        'R1-estimate-effectivity',
        'estimate the energy error without an exact solution (Richardson model, `study`) within [0.8, 1.25] of the '
        'true error at the finest two levels wherever its verdict says "in the asymptotic range", on every '
        'manufactured case (h: `mms_front`, `mms_rotated`, `mms_elastic`, `mms_stick_to_slip`, `mms_stop`; k: '
        '`mms_stop` N = 4^j against N = 4096 on the same mesh, corrected by 1/(1 − N/4096); joint: `mms_stop`), each '
        'kind in range at least once. Band from the issue; the verdict\'s tolerances (order within [p_th/2, p_th + '
        '0.15], GCI ratio within 10 % of rᵖ) are derived in `src/study/richardson.rs`',
        'verification/run_all.py --only estimates',
        'reference/estimates.md',
    ),
    Requirement(
        'R2-estimate-refuses',
        'say "not yet: refine further" on the coarsest level of `mms_front` (order 0.80 between refine 0 and 1) and on '
        'every level of `mms_stop` with N = 2^j (θ = frac(N/3) alternates)',
        'tresca-cr study verification/cases/mms_stop.toml --levels 3:4,3:8,3:16,3:32 --reference 3:4096',
        'reference/estimates.md',
    ),
    Requirement(
        'R3-differences',
        "write with `--differences DIR` one XDMF file per level with the elementwise energy density of u_l − P u_{l−1} "
        "as a cell field that meshio and VTK's vtkXdmfReader (ParaView's XDMF Reader) open",
        'tresca-cr study verification/cases/paper_example_5_1.toml --levels 0:40,1:80,2:160 --differences '
        'out/verify/differences',
        None,
    ),
    Requirement(
        'P3-paper-estimate',
        "estimate the error of Example 5.1's n = 32 level from the five levels of Table 5.1 alone within 20 % of its "
        "error against the n = 256 reference run",
        'as P2',
        'reference/paper_tables.md',
    ),
    Requirement(
        'A1-effectivity',
        'keep the adaptive indicator\'s effectivity η/|||u − u_h||| ≥ 1 and its max/min ≤ 1.05²·(DOF_last/DOF_0)^0.05 '
        'over 17 adapted levels (θ = 0.5) of `mms_elastic` and `mms_stick_to_slip` and 24 of `mms_lshape`: reliability '
        'and efficiency make it mesh-independent; allowed are a rate difference of 0.05 between η and the error (the '
        'fit band of A2) and Dörfler\'s ±5 % scatter per level at both ends',
        'tresca-cr adapt verification/cases/mms_elastic.toml --levels 17 --theta 0.5 --csv …',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A2-rate',
        '… and converge there at the optimal rate: true error ∝ DOF^(−1/2), fitted over levels 9–16 (`mms_lshape`: '
        '9–23) within 0.05, the last two rates over 3-level windows (levels 4, 7, …, 16; `mms_lshape`: …, 22) within '
        '0.12 (±5 % Dörfler scatter at both ends of a ×2.3 window)',
        'as A1',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A3-example-5-1',
        'on Example 5.1, against a generation-12 reference and in the same study, converge adaptively like DOF^(−1/2) '
        '± 0.05 (3-level windows ± 0.12) where uniform refinement gives DOF^(−0.43) ± 0.05 (the issue\'s order '
        '0.85–0.87 in h; pairs of levels), the adaptive rate the larger; only levels with ≤ the DOF of uniform '
        'generation 8 (the reference\'s error ≤ 0.3 of theirs)',
        'tresca-cr adapt verification/cases/paper_example_5_1.toml --levels 16 --theta 0.5 --reference 12; … --levels '
        '9 --theta 1 --reference 12',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A4-lshape-dof',
        'on the manufactured L-shape (`mms_lshape`, Gmsh, the re-entrant corner\'s r^0.5445 Williams singularity, true '
        'errors) reach the uniform route\'s finest accuracy (uniform level 12, 1.7 M unknowns) with at most a tenth of '
        'its unknowns (issue 33\'s bar; log-log interpolation between adaptive levels); the ratio at every uniform '
        'level and the uniform rates over level pairs reported; the physical `lshape_adapt` (against a generation-10 '
        'reference) reported in study.md without a bar',
        'tresca-cr adapt verification/cases/mms_lshape.toml --levels 24 --theta 0.5; … --levels 13 --theta 1',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A5-min-angle',
        'keep every adapted level\'s minimum angle at or above newest-vertex bisection\'s bound, the smallest angle '
        'over six generations of bisecting each initial triangle (computed in Python, `tresca_py/bisection.py`), on '
        'the structured meshes (`mms_elastic`, `mms_stick_to_slip`, Example 5.1) and the Gmsh L-shapes (`mms_lshape`, '
        '`lshape_adapt`), adaptive and uniform routes',
        'verification/run_all.py --only adaptive',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A6-adapted-mesh',
        'write each adapted level\'s mesh as Gmsh (`adapt --out DIR --gmsh`: the same points and triangles as '
        '`level_<k>.h5`), on which the scikit-fem and dolfinx re-implementations agree with the Rust solver to ≤ 1e-8 '
        '(DOF vectors, energies, σ_τ; no differing stick/slip flag), as does the adapt run\'s own level file',
        'verification/run_all.py --only adaptive',
        'reference/adaptive/study.md',
    ),
    Requirement(
        'A7-estimate',
        'report with every adapted level an error estimate (`adapt::estimate`) whose effectivity E / error lies in '
        '[0.8, 1.25] at every level past the first four on `mms_lshape` (24 levels) and `mms_data_front` (20; true '
        'errors) and on Example 5.1 (16, against its generation-12 reference) (issue 42); `adapt --target` stops on it',
        'verification/run_all.py --only adaptive',
        'reference/adaptive/study.md',
    ),
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
        "(also in `make test`, skipped with a message where pvpython is absent)",
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
        'Chouly–Ern–Pignet solution at λ = 3 on a Gmsh pentagon) the Richardson limits of GetFEM P1/P2/Taylor–Hood, an '
        'independent scikit-fem P2 Nitsche solver and tresca-cr (‖u‖_H1, ½a(u,u), u·τ at three points, ∫σ_τ, '
        'stick-zone ends, max slip) agree pairwise within the sum of their GCI bands (about 6 min)',
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


def find(rid):
    """The requirement a recorded result id belongs to; KeyError when none declares it."""
    found = [r for r in REQUIREMENTS if r.matches(rid)]
    if len(found) != 1:
        raise KeyError("result id "
                       f"{rid!r} matches {len(found)} declared requirements (tresca_py/verify/requirements.py)")
    return found[0]

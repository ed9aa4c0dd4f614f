"""Stability of tresca-cr at the extremes (issue 7) -> reference/stability.md; exit status 1 on any FAIL.

    .venv/bin/python verification/stability.py [--json OUT] [--md FILE] [--only case_nu,...]

(verification/stability.py is the entry point; ``main`` the report, ``harness`` the runs, ``p1`` the
reference solver and eigenvalues, ``material`` and ``extremes`` the cases.)
Each case records its requirements S<i>-stability in a
harness (:class:`Stability`: the temporary directory, the results files written and the harness, passed
to every case; no module-level state).
Each case states the expected behaviour, what was measured (release CLI; results read back from the HDF5
file), and PASS/FAIL. Scenes are derived from repository scenes by replacing single values in their text
(E, nu, g_a, rho, T, corners, cells), written to a temporary directory. The near-incompressible
manufactured case is verification/cases/near_incompressible.toml (tresca_py.mms.near_incompressible;
written when missing or with --regenerate): u = t·curl ψ, ψ = 100 (x(1−x)y(1−y))², div u = 0, all sides clamped, μ = 1
(E = 2(1+ν)), so f = −μΔu does not depend on ν and the exact solution is the same for every ν.
"""

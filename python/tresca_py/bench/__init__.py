"""Everything `make bench` runs (timings live here only; no pass/fail of make test or make verify depends on
them): ``report`` (reference/performance.md, verification/bench/report.py), ``timing`` (interleaved timed runs),
``interleave`` (two binaries compared, verification/interleave.py), ``factorisation`` and ``peers`` (the
factorisation bench against CHOLMOD, PARDISO and MUMPS, verification/bench/factorisation.py),
``planner_share`` (the planner's share of a run, verification/bench/planner_share.py)."""

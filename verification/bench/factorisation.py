"""make bench-factorisation: Example 5.1's reduced stiffness set up by tresca-cr, CHOLMOD, PARDISO and MUMPS,
interleaved (issue 32). Logic: python/tresca_py/bench/factorisation.py. Run in .venv-bench (make bench-env).

    .venv-bench/bin/python verification/bench/factorisation.py --refine 6 7 8 [--rounds 2] [--json out.json]
"""
from tresca_py.bench.factorisation import main

if __name__ == "__main__":
    main()

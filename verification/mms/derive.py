#!/usr/bin/env python3
"""Manufactured Tresca problems with exact solutions for tresca-cr (the logic: tresca_py/mms/, its command
line tresca_py/mms/cli.py).

Run from the repository root:

    .venv/bin/python verification/mms/derive.py            # derive, check, write verification/cases/*.toml
    .venv/bin/python verification/mms/derive.py --check    # derive and check only, write nothing
    .venv/bin/python verification/mms/derive.py --no-selftest   # skip the mutant self-test (halves the time)
    .venv/bin/python verification/mms/derive.py --exmex BIN   # also evaluate every emitted string with a
                                                              # real exmex binary (see README.md)

For every case an exact displacement u(x, y, t) is chosen; sympy then derives

    f   = -div sigma(u)                  body force,
    g   = sigma(u) n                     traction on every Neumann side,
    g_a (time independent)               friction bound on Gamma_C,
    u0  = u(., 0)                        initial value,
    grad u                               for the solver's true-error computation,

prints all of them in the syntax of the Rust `exmex` crate, parses the printed strings back
into sympy and compares them numerically with the originals, and then CHECKS the strong form of
the problem pointwise on fine grids in space and time (equilibrium, u = 0 on Gamma_D, u.n = 0 on
Gamma_C, |sigma_t| <= g_a, stick where |sigma_t| < g_a, u_t' = -theta sigma_t with theta >= 0
where slipping, compatibility of u0). Any failed check aborts with a non-zero exit status and no
file is written.

Conventions (those of README.md of the repository): n outward unit normal, tau = (-n_y, n_x),
sigma_t = sigma(u) n - (sigma(u) n . n) n; the solver reports sigma_t . tau and the slip u . tau.

Piecewise building blocks (all C^2 in their argument, so u(., t) is in H^2 and even W^{3,inf}):
  PosPow(z, n) = max(0, z)^n                 (n = 3 in the solutions; derivatives n PosPow(z, n-1))
  SStep(z, d)  = d-th derivative of S(min(max(z, 0), 1)),  S(c) = 10c^3 - 15c^4 + 6c^5
They are sympy Functions with explicit derivative rules, so sympy differentiates them exactly, and
the printer writes them with max/min. Derivatives that are discontinuous (Heaviside-like) are never
printed; they only occur in the time derivatives used by the checks.

Everything is exact rational arithmetic until the numerical checks, so the output is deterministic.
"""
from tresca_py.mms.cli import main

if __name__ == "__main__":
    main()

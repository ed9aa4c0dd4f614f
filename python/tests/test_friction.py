"""The per-step friction problem (tresca_py.skfem_cr.friction): the exact box-QP solver against its KKT
conditions and against an independent bounded least-squares oracle (scipy's BVLS)."""
import numpy as np
from scipy.optimize import lsq_linear

from tresca_py.skfem_cr.friction import box_qp, classify, kkt_residual


def random_problem(rng, n, zero_bounds=True):
    A = rng.standard_normal((n, n))
    C = A @ A.T + 1e-2 * np.eye(n)
    d = rng.standard_normal(n) * rng.uniform(0.1, 10)
    w = rng.uniform(0, 2, n)
    if zero_bounds:
        w[rng.random(n) < 0.1] = 0.0
    return C, d, w


def test_the_system_shall_solve_the_box_qp_to_its_kkt_conditions():
    rng = np.random.default_rng(1)
    worst = 0.0
    for trial in range(300):
        n = int(rng.integers(1, 30))
        C, d, w = random_problem(rng, n)
        mu, _ = box_qp(C, d, w, rng.uniform(-2, 2, n) if trial % 2 else None)
        g = C @ mu - d
        feas = np.max(np.maximum(np.abs(mu) - w, 0))
        inside = np.abs(mu) < w
        # KKT: g = 0 inside the box, g <= 0 at +w, g >= 0 at -w
        kkt = max(np.max(np.abs(g[inside]), initial=0), np.max(g[(mu >= w) & (w > 0)], initial=0),
                  np.max(-g[(mu <= -w) & (w > 0)], initial=0))
        worst = max(worst, feas, kkt / (np.abs(d).max() + np.abs(C).max() * w.max()))
        assert kkt_residual(C, d, w, mu) < 1e-12
    # the stopping test is 1e-14 of this scale; the solves of n <= 30 SPD systems add a few ulps of cond(C)
    assert worst < 1e-12, worst


def test_the_system_shall_agree_with_an_independent_bounded_least_squares_solver():
    rng = np.random.default_rng(7)
    for _ in range(50):
        n = int(rng.integers(1, 25))
        C, d, w = random_problem(rng, n, zero_bounds=False)
        w = np.maximum(w, 1e-3)
        mu, _ = box_qp(C, d, w)
        # 1/2 mu^T C mu - mu^T d = 1/2 |L^T mu - L^{-1} d|^2 + const with C = L L^T
        L = np.linalg.cholesky(C)
        ref = lsq_linear(L.T, np.linalg.solve(L, d), bounds=(-w, w), method="bvls", tol=1e-15,
                         max_iter=10000).x
        # both exact active-set methods: the minimiser is unique (C SPD); difference = rounding of the
        # final face solve, relative to cond(C) ~ 1e4 at most here
        assert np.max(np.abs(mu - ref)) <= 1e-9 * max(1.0, np.max(np.abs(ref))), (n, np.max(np.abs(mu - ref)))


def test_the_system_shall_classify_slip_only_at_the_bound_with_a_moving_edge():
    w = np.array([1.0, 1.0, 1.0, 0.0])
    mu = np.array([1.0, 0.5, -1.0, 0.0])
    ds = np.array([0.3, 0.0, 0.0, -0.2])
    d = np.array([1.0, 0.0, 0.0, 0.0])
    assert classify(mu, ds, d, w).tolist() == [True, False, False, True]


def test_the_dolfinx_step_solver_shall_reach_the_exact_box_qp_solution_with_tao():
    from tresca_py.dolfinx_cr.friction import TaoBoxQP
    rng = np.random.default_rng(11)
    for trial in range(100):
        n = int(rng.integers(1, 30))
        C, d, w = random_problem(rng, n)
        ref, _ = box_qp(C, d, w)
        mu, _ = TaoBoxQP(C, w).solve(d, rng.uniform(-2, 2, n) if trial % 2 else np.zeros(n))
        # TRON stops at a projected gradient of 1e-13 of |d| + |C||w|; with cond(C) <= ~1e5 here the
        # minimiser is then known to ~1e-8 relative at worst (measured: 4.9e-15, at most 7 TRON iterations)
        assert np.max(np.abs(mu - ref)) <= 1e-8 * max(1.0, np.max(np.abs(ref))), trial

//! The primal–dual active-set method of Hintermüller, Ito & Kunisch (SIAM J. Optim. 13(3), 2003) for the
//! condensed QP with normal unknowns (`normal`: unilateral Tresca, frictionless contact), safeguarded by
//! Bertsekas' projected Newton method (`ssn`).
//!
//! It is semismooth Newton on the NCP function λ − P_[lo,hi](λ + cΔ), Δ = d − Cλ, c_k = 1/C_kk: each
//! iteration takes the sets of y = λ + cΔ (upper: y > hi, λ = hi; lower: y < lo, λ = lo; inactive: the
//! rest, Δ = 0) and solves the linear system they give, C_II λ_I = d_I − C_IA λ_A (one Cholesky), so the
//! whole set may move at once. After a Newton step Δ = 0 on I and λ is at its bound on A, so the next sets
//! depend on signs only (a force beyond its bound leaves I, a bound whose Δ pushes back into the box is
//! released), not on c, whose diagonal scale C_kk misjudges the force a smooth Δ needs by a factor that
//! grows with 1/h. Where a front of the start is wrong, it still moves about one edge per Newton step (the
//! forces of a too-large stick or contact zone exceed their bounds only next to its end); the projected
//! Newton method moves it no faster, at several Armijo trials a step.
//!
//! The start. A warm start λ₀ ≠ 0 (the previous step's forces) gives the first sets from λ₀ itself (at a
//! bound: that bound; otherwise inactive), the sets of the step it solved, as `coulomb` does: a step whose
//! sets did not change is solved by one Newton step. Where that step does not solve it, and from λ₀ = 0,
//! the iteration goes on from the sets of the nested iteration (`nested`), whose fronts are within a couple
//! of edges of the solution's at every h (without coarse levels: those of y = λ + cΔ).
//!
//! The safeguard. Iterates need not be feasible; the one reported and tested is P(λ), to the scene's
//! tolerance on the natural residual (`super::Qp::residual`). A set that repeats (plain PDAS can cycle
//! where C is not an M-matrix, `pdas`), [`STALE`] iterations without a new best residual, or a singular
//! C_II hand the best feasible iterate to `ssn`, which is monotone in q and cannot cycle.

use super::nested::{Levels, COARSE_ITER};
use super::{ssn, stalled, Qp, Solved};
use crate::scene::Method;
use nalgebra::{DMatrix, DVector};
use std::collections::HashSet;

/// Iterations without a new best natural residual after which the safeguard takes over.
const STALE: usize = 8;

/// A force within this fraction of a nonzero bound is at it (the warm start's sets).
const AT_BOUND: f64 = 1e-12;

/// Solve the QP from the warm start `mu0` to natural residual ≤ tol, with the predictor of `levels`.
pub fn solve(qp: &Qp, mu0: &[f64], tol: f64, max_iter: usize, levels: &Levels) -> Solved {
    let lam: Vec<f64> = (0..qp.d.len()).map(|k| qp.project(k, mu0[k])).collect();
    let predict = || predicted(qp, levels, tol);
    if lam.iter().any(|v| *v != 0.0) {
        let first = warm_set(qp, &lam);
        iterate(qp, lam, Some(first), Some(&predict), tol, max_iter)
    } else {
        iterate(qp, lam, predict(), None, tol, max_iter)
    }
}

/// The nested iteration's sets for the fine problem (`nested`; `None` without coarse levels or where a
/// level does not converge).
fn predicted(qp: &Qp, levels: &Levels, tol: f64) -> Option<Vec<i8>> {
    let nc = qp.d.len() / 2;
    let mut sets: Option<Vec<i8>> = None;
    for l in (1..=levels.len()).rev() {
        let co = levels.coarse(l, qp.c, qp.d, &qp.lo[nc..], &qp.hi[..nc], &vec![None; nc]);
        let cq = Qp { c: &co.c, d: &co.d, lo: &co.lo, hi: &co.hi };
        let start = sets.map(|s| levels.prolong(l + 1, l, &s));
        let (lam, _, _) = iterate(&cq, vec![0.0; co.d.len()], start, None, tol, COARSE_ITER).ok()?;
        sets = Some(warm_set(&cq, &lam));
    }
    sets.map(|s| levels.prolong(1, 0, &s))
}

/// The iteration from the feasible λ₀ and the first sets `first` (`None`: those of λ₀'s y); where the
/// first Newton step does not solve the problem, `retry` gives the sets of the second.
fn iterate(
    qp: &Qp,
    mut lam: Vec<f64>,
    mut set: Option<Vec<i8>>,
    retry: Option<&dyn Fn() -> Option<Vec<i8>>>,
    tol: f64,
    max_iter: usize,
) -> Solved {
    let n = qp.d.len();
    let project = |v: &[f64]| -> Vec<f64> { (0..n).map(|k| qp.project(k, v[k])).collect() };
    let mut seen: HashSet<Vec<i8>> = HashSet::new();
    let (mut best, mut best_res, mut stale) = (lam.clone(), f64::INFINITY, 0);
    for it in 0..=max_iter {
        let mu = project(&lam);
        let ds_mu = qp.slip_increment(&mu);
        let res = qp.residual(&mu, &ds_mu);
        if res <= tol {
            return Ok((mu, it, res));
        }
        if it == max_iter {
            return Err(stalled(Method::Ssn.name(), it, res));
        }
        if res < best_res {
            (best, best_res, stale) = (mu.clone(), res, 0);
        } else {
            stale += 1;
        }
        if it == 1 {
            set = retry.and_then(|r| r()).filter(|s| !seen.contains(s));
        }
        let s = set.take().unwrap_or_else(|| {
            let ds = if mu == lam { ds_mu } else { qp.slip_increment(&lam) };
            sets(qp, &lam, &ds)
        });
        let next = if stale < STALE && seen.insert(s.clone()) { newton_step(qp, &s) } else { None };
        match next {
            Some(l) => lam = l,
            None => {
                return ssn::solve(qp, &best, tol, max_iter - it)
                    .map(|(m, k, r)| (m, it + k, r))
                    .map_err(|e| stalled(e.solver, it + e.iterations, e.residual))
            }
        }
    }
    unreachable!("the loop returns at it == max_iter")
}

/// The set of each unknown: 1 at its upper bound, −1 at its lower one, 0 inactive; a fixed unknown
/// (lo = hi: a frictionless tangential force) is at its upper bound.
fn set_of(qp: &Qp, k: usize, above: bool, below: bool) -> i8 {
    if qp.lo[k] == qp.hi[k] || above {
        1
    } else if below {
        -1
    } else {
        0
    }
}

/// The sets of the warm start λ₀ (feasible): at a bound to [`AT_BOUND`], or inactive.
fn warm_set(qp: &Qp, lam: &[f64]) -> Vec<i8> {
    let at = |v: f64, b: f64| b.is_finite() && (v == b || (v - b).abs() <= AT_BOUND * b.abs());
    (0..lam.len()).map(|k| set_of(qp, k, at(lam[k], qp.hi[k]), at(lam[k], qp.lo[k]))).collect()
}

/// The sets of y = λ + Δ/C_kk (Δ = `ds`).
fn sets(qp: &Qp, lam: &[f64], ds: &[f64]) -> Vec<i8> {
    (0..lam.len())
        .map(|k| {
            let y = lam[k] + ds[k] / qp.c[(k, k)];
            set_of(qp, k, y > qp.hi[k], y < qp.lo[k])
        })
        .collect()
}

/// The iterate of the sets `set`: λ_A at its bounds, C_II λ_I = d_I − C_IA λ_A (`None`: C_II is not
/// numerically positive definite, or the result is not finite).
fn newton_step(qp: &Qp, set: &[i8]) -> Option<Vec<f64>> {
    let n = set.len();
    let mut lam: Vec<f64> = (0..n)
        .map(|k| match set[k] {
            1 => qp.hi[k],
            -1 => qp.lo[k],
            _ => 0.0,
        })
        .collect();
    let free: Vec<usize> = (0..n).filter(|&k| set[k] == 0).collect();
    if !free.is_empty() {
        let rhs = qp.slip_increment(&lam);
        let cff = DMatrix::from_fn(free.len(), free.len(), |i, j| qp.c[(free[i], free[j])]);
        let x = cff.cholesky()?.solve(&DVector::from_iterator(free.len(), free.iter().map(|&k| rhs[k])));
        for (i, &k) in free.iter().enumerate() {
            lam[k] = x[i];
        }
    }
    lam.iter().all(|v| v.is_finite()).then_some(lam)
}

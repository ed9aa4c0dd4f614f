//! The plain primal–dual active-set iteration (semismooth Newton on μ = P(μ + c Δs) without
//! globalisation), for diagnostics: with c_e = 1/C_ee,
//!   slip⁺ = {μ + cΔs > w}, slip⁻ = {μ + cΔs < −w}: μ_e = ±w_e;   stick = rest: Δs_e = 0,
//! i.e. C_SS μ_S = d_S − C_{S,slip} μ_slip. Because C is not an M-matrix this can cycle between active
//! sets; a repeated set is reported as non-convergence instead of iterating on.

use super::{stalled, Qp, Solved};
use nalgebra::{DMatrix, DVector};
use std::collections::HashSet;

/// Solve the QP by plain PDAS from `mu0`.
pub fn solve(qp: &Qp, mu0: &[f64], tol: f64, max_iter: usize) -> Solved {
    let n = qp.d.len();
    let mut mu = mu0.to_vec();
    let mut seen: HashSet<Vec<i8>> = HashSet::new();
    for it in 0..=max_iter {
        let ds = qp.slip_increment(&mu);
        // |μ_e| ≤ w_e(1 + 1e-14) on a box; on [lo, hi] each bound widened by the same factor
        let feasible = (0..n).all(|e| mu[e] <= qp.hi[e] * (1.0 + 1e-14) && mu[e] >= qp.lo[e] * (1.0 + 1e-14));
        let res = if feasible { qp.residual(&mu, &ds) } else { f64::INFINITY };
        if res <= tol {
            return Ok((mu, it, res));
        }
        let set: Vec<i8> = (0..n)
            .map(|e| {
                let y = mu[e] + ds[e] / qp.c[(e, e)];
                if y > qp.hi[e] {
                    1
                } else if y < qp.lo[e] {
                    -1
                } else {
                    0
                }
            })
            .collect();
        if it == max_iter || !seen.insert(set.clone()) {
            let what = if it == max_iter { "pdas" } else { "pdas (cycling: an active set repeated)" };
            return Err(stalled(what, it, res));
        }
        let stick: Vec<usize> = (0..n).filter(|&e| set[e] == 0).collect();
        for e in 0..n {
            if set[e] != 0 {
                mu[e] = if set[e] > 0 { qp.hi[e] } else { qp.lo[e] };
            }
        }
        if !stick.is_empty() {
            let css = DMatrix::from_fn(stick.len(), stick.len(), |i, j| qp.c[(stick[i], stick[j])]);
            let rhs = DVector::from_iterator(
                stick.len(),
                stick
                    .iter()
                    .map(|&i| qp.d[i] - (0..n).filter(|&j| set[j] != 0).map(|j| qp.c[(i, j)] * mu[j]).sum::<f64>()),
            );
            let sol = css.cholesky().ok_or_else(|| stalled("pdas (singular stick block)", it, res))?.solve(&rhs);
            for (k, &e) in stick.iter().enumerate() {
                mu[e] = sol[k];
            }
        }
    }
    unreachable!("the loop returns at it == max_iter")
}

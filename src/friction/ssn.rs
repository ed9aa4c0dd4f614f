//! Semismooth Newton for the condensed friction QP (see `friction`): Bertsekas' projected Newton method.
//!
//! Each iteration splits the edges into an ε-active set A (at a bound, with the gradient g = Cμ − d pushing
//! outward) and a free set F, takes the Newton step p_F = −C_FF⁻¹ g_F on F and a scaled gradient step
//! p_A = −g_A / diag(C)_A on A, and searches along the projection arc μ(α) = P(μ + αp) with an Armijo rule
//! on q. The iterates are feasible and q decreases monotonically, so the method cannot cycle (a plain
//! primal–dual active-set iteration can, see `pdas`); once the active set is identified the full Newton
//! step is accepted and the iteration terminates at the exact solution (residual at rounding level).
//! With normal unknowns it is the safeguard of the primal–dual active-set method of `hik`.

use super::{stalled, Qp, Solved};
use crate::scene::Method;
use nalgebra::{DMatrix, DVector};

/// Armijo sufficient-decrease constant.
const SIGMA: f64 = 1e-4;

/// Solve the QP from the warm start `mu0` to natural residual ≤ tol.
pub fn solve(qp: &Qp, mu0: &[f64], tol: f64, max_iter: usize) -> Solved {
    let n = qp.d.len();
    let mut mu: Vec<f64> = (0..n).map(|e| qp.project(e, mu0[e])).collect();
    let fscale = qp.force_scale();
    for it in 0..=max_iter {
        let ds = qp.slip_increment(&mu);
        let res = qp.residual(&mu, &ds);
        if res <= tol {
            return Ok((mu, it, res));
        }
        if it == max_iter {
            return Err(stalled(Method::Ssn.name(), it, res));
        }
        let g: Vec<f64> = ds.iter().map(|v| -v).collect();
        // ε-active set (Bertsekas 1982): ε = min(ε₀, ‖μ − P(μ − D⁻¹g)‖)
        let eps = (0..n)
            .map(|e| (mu[e] - qp.project(e, mu[e] - g[e] / qp.c[(e, e)])).abs())
            .fold(0.0, f64::max)
            .min(1e-3 * fscale);
        let active: Vec<bool> = (0..n)
            .map(|e| {
                (mu[e] >= qp.hi[e] - eps && g[e] < 0.0)
                    || (mu[e] <= qp.lo[e] + eps && g[e] > 0.0)
                    || qp.lo[e] == qp.hi[e]
            })
            .collect();
        let free: Vec<usize> = (0..n).filter(|&e| !active[e]).collect();
        let mut p: Vec<f64> = (0..n).map(|e| if active[e] { -g[e] / qp.c[(e, e)] } else { 0.0 }).collect();
        if !free.is_empty() {
            let cff = DMatrix::from_fn(free.len(), free.len(), |i, j| qp.c[(free[i], free[j])]);
            let rhs = DVector::from_iterator(free.len(), free.iter().map(|&e| -g[e]));
            let chol =
                cff.cholesky().ok_or_else(|| stalled("ssn (condensed operator not positive definite)", it, res))?;
            let pf = chol.solve(&rhs);
            for (k, &e) in free.iter().enumerate() {
                p[e] = pf[k];
            }
        }
        // Armijo search along the projection arc
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..60 {
            let trial: Vec<f64> = (0..n).map(|e| qp.project(e, mu[e] + alpha * p[e])).collect();
            let delta: Vec<f64> = (0..n).map(|e| trial[e] - mu[e]).collect();
            // q(μ+δ) − q(μ) = gᵀδ + ½ δᵀCδ
            let cd = qp.c * DVector::from_column_slice(&delta);
            let dq: f64 = (0..n).map(|e| delta[e] * (g[e] + 0.5 * cd[e])).sum();
            let pred: f64 =
                (0..n).map(|e| if active[e] { g[e] * (mu[e] - trial[e]) } else { -alpha * g[e] * p[e] }).sum();
            if -dq >= SIGMA * pred || delta.iter().all(|v| *v == 0.0) {
                mu = trial;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            return Err(stalled("ssn (line search failed)", it, res));
        }
    }
    unreachable!("the loop returns at it == max_iter")
}

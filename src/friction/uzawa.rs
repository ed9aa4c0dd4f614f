//! The paper's Uzawa iteration (section 5) on the condensed friction problem: with the multiplier
//! λ_e ∈ [−1, 1] (friction force μ_e = w_e λ_e) and c_τ = ḡ_e,
//!   λᵏ = P(λᵏ⁻¹ + ρ̃ ḡ_e Δs_e(μᵏ⁻¹)),   P(χ) = max(−1, min(1, χ)),
//! stopped when successive multipliers differ by less than tol (max norm). Each iteration needs
//! Δs = d − Cμ, which is exactly the contact trace of K⁻¹(l − Eμ) with the once-factored K.
//! The iteration converges for 0 < ρ̃ < 2/λ_max(M), M = (GW)^{1/2} C (GW)^{1/2}, G = diag(ḡ), W = diag(w);
//! `step = 0` chooses ρ̃ = 1/λ_max(M) (power iteration).

use super::{stalled, Qp, Solved};
use crate::scene::Method;

/// ρ̃ = 1/λ_max((GW)^{1/2} C (GW)^{1/2}) by power iteration.
pub fn auto_step(qp: &Qp, g: &[f64]) -> f64 {
    let n = qp.d.len();
    let s: Vec<f64> = (0..n).map(|e| (g[e] * qp.half_width(e)).sqrt()).collect();
    let mut v = vec![1.0 / (n as f64).sqrt(); n];
    let mut lam = 0.0;
    for _ in 0..200 {
        let sv: Vec<f64> = (0..n).map(|e| s[e] * v[e]).collect();
        let mut y: Vec<f64> = (0..n).map(|i| (0..n).map(|j| qp.c[(i, j)] * sv[j]).sum::<f64>() * s[i]).collect();
        let norm = y.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            return 1.0;
        }
        y.iter_mut().for_each(|x| *x /= norm);
        let done = (norm - lam).abs() <= 1e-6 * norm;
        lam = norm;
        v = y;
        if done {
            break;
        }
    }
    1.0 / lam
}

/// Uzawa from the warm start `mu0` with step `rho` (the paper's ρ̃).
pub fn solve(qp: &Qp, g: &[f64], mu0: &[f64], rho: f64, tol: f64, max_iter: usize) -> Solved {
    let n = qp.d.len();
    let mut lam: Vec<f64> = (0..n)
        .map(|e| if qp.half_width(e) > 0.0 { (mu0[e] / qp.half_width(e)).clamp(-1.0, 1.0) } else { 0.0 })
        .collect();
    let mut mu: Vec<f64> = (0..n).map(|e| qp.half_width(e) * lam[e]).collect();
    let mut diff = f64::INFINITY;
    for it in 1..=max_iter {
        let ds = qp.slip_increment(&mu);
        diff = 0.0;
        for e in 0..n {
            let new = (lam[e] + rho * g[e] * ds[e]).clamp(-1.0, 1.0);
            diff = diff.max((new - lam[e]).abs());
            lam[e] = new;
            mu[e] = qp.half_width(e) * new;
        }
        if !diff.is_finite() {
            break;
        }
        if diff < tol {
            let res = qp.residual(&mu, &qp.slip_increment(&mu));
            return Ok((mu, it, res));
        }
    }
    Err(stalled(Method::Uzawa.name(), max_iter, diff))
}

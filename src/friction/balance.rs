//! Can the contact forces balance a floating body's loads at all? The smallest unbalanced load
//!   r* = e − Gᵀλ*,   λ* = argmin ½|Gᵀλ − e|² over the admissible forces Λ
//! (Tresca's box |μ_e| ≤ w_e, P_e ≥ 0 on a unilateral edge, Coulomb's cone |μ_e| ≤ F̄_e |P_e|) is zero
//! exactly when some admissible λ balances them; otherwise it is the net load (in R's coordinates)
//! that no contact force can take, and the rigid motion it pushes along is the one that is free. Λ is
//! closed and convex on unilateral and Tresca edges (a bilateral Coulomb edge is projected onto the
//! half of its double cone that holds P_e), G has orthonormal columns, so projected gradient steps of
//! length 1 (accelerated, FISTA) converge to r*, which is unique.

use nalgebra::DMatrix;

/// Projected gradient iterations.
const ITERATIONS: usize = 4000;

/// The admissible contact forces: per Γ_C edge Tresca's bound or Coulomb's coefficient, and the normal
/// forces' lower bounds (empty without normal unknowns).
pub struct Admissible<'a> {
    pub w: &'a [f64],
    pub coulomb: &'a [Option<f64>],
    pub lo: &'a [f64],
}

impl Admissible<'_> {
    /// λ projected onto Λ (in place).
    fn project(&self, lam: &mut [f64]) {
        let nc = self.w.len();
        let normal = !self.lo.is_empty();
        for e in 0..nc {
            if normal {
                lam[nc + e] = lam[nc + e].max(self.lo[e]);
            }
            match (self.coulomb.get(e).copied().flatten(), normal) {
                (Some(f), true) => {
                    let (mu, p) = (lam[e], lam[nc + e]);
                    let s = if p < 0.0 && self.lo[e] < 0.0 { -1.0 } else { 1.0 };
                    let (pn, m) = (s * p, mu.abs());
                    let (pn, m) = if m <= f * pn {
                        (pn, m)
                    } else if f * m <= -pn {
                        (0.0, 0.0)
                    } else {
                        let q = (pn + f * m) / (1.0 + f * f);
                        (q, f * q)
                    };
                    lam[e] = m.copysign(mu);
                    lam[nc + e] = s * pn;
                }
                _ => lam[e] = lam[e].clamp(-self.w[e], self.w[e]),
            }
        }
    }
}

/// r* = e − Gᵀλ* from the start λ₀ (G: rows the contact unknowns, orthonormal columns).
pub fn unbalanced(g: &DMatrix<f64>, e: &[f64], set: &Admissible, lam0: &[f64]) -> Vec<f64> {
    let k = g.ncols();
    let residual = |lam: &[f64]| -> Vec<f64> {
        (0..k).map(|j| e[j] - (0..lam.len()).map(|i| g[(i, j)] * lam[i]).sum::<f64>()).collect()
    };
    let mut lam = lam0.to_vec();
    set.project(&mut lam);
    let (mut prev, mut y, mut t) = (lam.clone(), lam.clone(), 1.0f64);
    for _ in 0..ITERATIONS {
        // gradient of ½|Gᵀy − e|² is −G r(y); a step of 1 (‖G‖ = 1)
        let r = residual(&y);
        lam = (0..y.len()).map(|i| y[i] + (0..k).map(|j| g[(i, j)] * r[j]).sum::<f64>()).collect();
        set.project(&mut lam);
        let t1 = 0.5 * (1.0 + (1.0 + 4.0 * t * t).sqrt());
        y = (0..lam.len()).map(|i| lam[i] + (t - 1.0) / t1 * (lam[i] - prev[i])).collect();
        prev.clone_from(&lam);
        t = t1;
    }
    residual(&lam)
}

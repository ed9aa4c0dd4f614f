//! The adaptive route's error estimate: the indicator η calibrated, level by level, against a Richardson
//! estimate along the sequence in the number of unknowns N.
//!
//! **Richardson along the sequence.** Dörfler marking with newest-vertex bisection converges at the
//! optimal rate N^(−1/2) in the energy norm whatever the corners (Stevenson 2007; Cascon, Kreuzer,
//! Nochetto, Siebert 2008; for Crouzeix–Raviart, Carstensen and Hoppe 2006), and the broken-gradient
//! errors of nested levels are orthogonal increments to leading order, as on uniform meshes (`study`
//! measures β ≈ 1, `study::richardson`). Split the error of level k into its gradient part g_k and its
//! jump part J_k (the level's own jump energy against u_D: exactly the jump part of its true error, the
//! exact solution having none). Orthogonality gives g_{k−1}² = g_k² + G_k² with G_k² the broken energy of
//! u_k − u_{k−1}, and the rate g_k² ∝ 1/N_k, so g_k² (q_k − 1) = G_k² with q_k = N_k/N_{k−1}:
//!
//!   R_k = max over the time nodes of √(G_k²/(q_k^{2r} − 1) + J_k),   r = [`RATE`] = ½.
//!
//! (The distance `vs_next` adds the *coarse* level's jumps to G², which is why it is not used here.)
//!
//! **Calibration.** One level's R_k carries the noise of one increment (how much of the error a single
//! Dörfler step removed). η_k is smooth along the sequence and its effectivity drifts slowly (η/error
//! 5–6 over 24 levels on mms_lshape), so the estimate is η_k times the median of R_j/η_j over the last
//! [`WINDOW`] levels j ≤ k (j ≥ 1):
//!
//!   E_k = η_k · median{R_j/η_j : max(1, k + 1 − WINDOW) ≤ j ≤ k}.
//!
//! It uses only levels up to k (`adapt` reports it as soon as level k is solved), and its constants are
//! fixed by the theory above, not fitted to true errors: RATE is the optimal rate, and WINDOW = 8 levels
//! is a factor of about 8 in N at θ = ½. It holds where the route converges at the optimal rate, which
//! Dörfler marking ensures for any scene; it is not meant for θ = 1 (uniform) sequences, whose rate is
//! min(1, α)/2 in N.

use super::Row;

/// The energy-norm rate in N of adaptive refinement with Dörfler marking.
pub const RATE: f64 = 0.5;
/// Levels over which the calibration factor R/η is taken (the median).
pub const WINDOW: usize = 8;
/// The first level whose estimate is trusted (a stopping rule may use it): the first four are
/// pre-asymptotic (the effectivity is held to [0.8, 1.25] past them, `make verify`).
pub const TRUSTED_FROM: usize = 4;

/// R_k (module doc) from the squared gradient increment G² and level k's squared jump energy J at every
/// common time node, and the unknowns of levels k − 1 and k; `None` when the unknowns did not grow.
pub fn richardson(parts: &[(f64, f64)], coarse: usize, fine: usize) -> Option<f64> {
    let q = (fine as f64 / coarse as f64).powf(2.0 * RATE) - 1.0;
    (q > 0.0).then(|| parts.iter().fold(0.0f64, |m, &(g, j)| m.max((g / q + j).max(0.0).sqrt())))
}

/// E_k (module doc) for the last of `rows`, each with its η and its R (`Row::richardson`).
pub fn calibrated(rows: &[Row]) -> Option<f64> {
    let last = rows.last()?;
    let mut k: Vec<f64> = rows
        .iter()
        .rev()
        .take(WINDOW)
        .filter_map(|r| r.richardson.filter(|_| r.estimator > 0.0).map(|e| e / r.estimator))
        .collect();
    if k.is_empty() {
        return None;
    }
    k.sort_by(f64::total_cmp);
    let m = k.len();
    let median = if m % 2 == 1 { k[m / 2] } else { 0.5 * (k[m / 2 - 1] + k[m / 2]) };
    Some(last.estimator * median)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Errors g_k² = C/N_k with orthogonal increments and jump energies J_k: R_k gives back √(g_k² + J_k)
    /// exactly, and the calibrated estimate of a sequence whose η is a fixed multiple of the error is the
    /// error (any window); with one level it is unknown.
    #[test]
    fn richardson_recovers_orthogonal_errors_at_the_optimal_rate() {
        let n = [100usize, 130, 170, 220, 290];
        let g2 = |k: usize| 4.0 / n[k] as f64;
        let jump = |k: usize| 0.3 * g2(k);
        let mut rows = Vec::new();
        for k in 0..n.len() {
            let error = (g2(k) + jump(k)).sqrt();
            let r = (k > 0).then(|| richardson(&[(g2(k - 1) - g2(k), jump(k))], n[k - 1], n[k]).unwrap());
            if let Some(r) = r {
                assert!((r / error - 1.0).abs() < 1e-12, "level {k}: {r} against {error}");
            }
            rows.push(Row { unknowns: n[k], estimator: 5.0 * error, richardson: r, ..Row::default() });
            let e = calibrated(&rows);
            assert_eq!(e.is_none(), k == 0);
            if let Some(e) = e {
                assert!((e / error - 1.0).abs() < 1e-12, "level {k}: {e} against {error}");
            }
        }
        assert_eq!(richardson(&[(1.0, 0.0)], 100, 100), None);
    }

    /// The calibration is the median over the window: one wild level does not move it.
    #[test]
    fn calibration_ignores_one_outlier() {
        let rows: Vec<Row> = (0..5)
            .map(|k| Row { estimator: 1.0, richardson: Some(if k == 3 { 10.0 } else { 0.2 }), ..Row::default() })
            .collect();
        assert_eq!(calibrated(&rows), Some(0.2));
    }
}

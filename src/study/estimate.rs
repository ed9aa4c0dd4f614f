//! The energy-norm error of every level estimated without an exact solution ([`super::richardson`]).
//!
//! Sizes x: h when the levels' meshes differ (an h or a joint study), k when they share one (a k study,
//! whose limit is the semi-discrete solution on that mesh). At the common time node n* where the distance
//! b of the two finest levels peaks, the three finest levels' distances a, b, D fit the model
//! (p, β, C). At every common node the estimate of level l is then
//!   G_l = the coarse part of [`NormModel::estimate`] from its distance to level l+1 (l < L), or the fine
//!         part from its distance to level L−1 (l = L),
//!   E_l = √(G_l² + J_l) on different meshes (J_l: the level's own jump energy, exactly the jump part of
//!         its true error, since the exact u has no jumps), E_l = G_l on one mesh (a_h norm throughout),
//! reported as the max over the common nodes and the value at T, with GCI = 1.25 E (three levels or
//! more). The theoretical order is 1 in h (H² solutions) and 1 in k (backward Euler).

use super::richardson::{asymptotic, NormModel, Verdict, FS_THREE};
use super::{Axis, LevelResult};

/// The order the paper proves in h and in k.
pub const THEORETICAL_ORDER: f64 = 1.0;

/// The estimate of one level.
#[derive(Clone, Debug)]
pub struct LevelEstimate {
    /// Max over common nodes, and at T.
    pub error: [f64; 2],
    /// GCI of the max (absolute, energy units).
    pub gci: f64,
    pub verdict: Verdict,
}

/// The estimates of a study, or why there are none.
#[derive(Clone, Debug)]
pub struct Estimates {
    /// The axis the levels refine.
    pub size: Axis,
    pub model: Option<NormModel>,
    /// Per level (empty when no model).
    pub levels: Vec<LevelEstimate>,
    /// Why no estimate, when `model` is None.
    pub refused: Option<String>,
}

/// True when the levels share one mesh (a k study).
pub fn one_mesh(r: &[LevelResult]) -> bool {
    r.windows(2).all(|w| w[0].refine == w[1].refine)
}

/// The sizes x of the levels (h, or k on one mesh).
pub fn sizes(r: &[LevelResult]) -> (Axis, Vec<f64>) {
    if one_mesh(r) {
        (Axis::K, r.iter().map(|l| l.k).collect())
    } else {
        (Axis::H, r.iter().map(|l| l.h).collect())
    }
}

/// Estimates from the levels' distances (fields `increment`, `skip`, `jumps` of [`LevelResult`]).
pub fn estimate(r: &[LevelResult]) -> Estimates {
    let (size, x) = sizes(r);
    let refuse = |why: String| Estimates { size, model: None, levels: vec![], refused: Some(why) };
    let n = r.len();
    if n < 3 {
        return refuse("three levels are needed for an observed order".into());
    }
    if x.windows(2).any(|w| w[1] >= w[0]) {
        return refuse(format!("the sizes {size} must decrease from level to level"));
    }
    let (inc, skip) =
        (|l: usize| r[l].increment.as_deref().unwrap_or(&[]), |l: usize| r[l].skip.as_deref().unwrap_or(&[]));
    let b = inc(n - 1);
    let Some(star) = (0..b.len()).max_by(|&i, &j| b[i].total_cmp(&b[j])) else {
        return refuse("no common time nodes".into());
    };
    let (a, bb, dd) = (inc(n - 2)[star], b[star], skip(n - 1)[star]);
    let xs = [x[n - 3], x[n - 2], x[n - 1]];
    let Some(model) = NormModel::fit(xs, a, bb, dd) else {
        let why = if bb == 0.0 || bb <= 1e-12 * a {
            format!(
                "the two finest levels agree to rounding (distance {bb:.2e}) while the two before differ by {a:.2e}"
            )
        } else if bb >= a {
            format!("the finest distance {bb:.3e} is not below the previous one {a:.3e}: no convergence yet")
        } else {
            format!("no order in (0, 8] and β in [0, 4] fits the distances {a:.3e}, {bb:.3e}, {dd:.3e} of the three finest levels")
        };
        return refuse(why);
    };
    let errs = level_errors(r, &model);
    let verdicts = asymptotic(&x, model.p, &errs.iter().map(|e| e[0]).collect::<Vec<_>>(), THEORETICAL_ORDER);
    let levels =
        errs.iter().zip(verdicts).map(|(e, v)| LevelEstimate { error: *e, gci: FS_THREE * e[0], verdict: v }).collect();
    Estimates { size, model: Some(model), levels, refused: None }
}

/// The estimate (max over the common nodes, at T) of every level of `r` under `model` (module doc; at
/// least two levels, with their increments).
pub fn level_errors(r: &[LevelResult], model: &NormModel) -> Vec<[f64; 2]> {
    let (n, (_, x)) = (r.len(), sizes(r));
    let inc = |l: usize| r[l].increment.as_deref().unwrap_or(&[]);
    let spread = !one_mesh(r);
    let per_node = |l: usize| -> Vec<f64> {
        let g: Vec<f64> = if l + 1 < n {
            inc(l + 1).iter().map(|&d| model.estimate(x[l], x[l + 1], d).1).collect()
        } else {
            inc(l).iter().map(|&d| model.estimate(x[l - 1], x[l], d).0).collect()
        };
        g.iter().zip(&r[l].jumps).map(|(g, j)| if spread { (g * g + j).sqrt() } else { *g }).collect()
    };
    (0..n).map(|l| super::measure::max_last(&per_node(l))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Levels whose errors have orthogonal increments (|e_l| = 0.3 h_l, nested Galerkin) and jump energy
    /// J_l = (0.1 h_l)²: the estimate √(G² + J) equals the true √(|e_l|² + J_l) at every level, β = 1.
    #[test]
    fn estimate_recovers_errors_with_orthogonal_increments() {
        let h = [0.4, 0.2, 0.1, 0.05];
        let e = |x: f64| 0.3 * x;
        let inc = |i: usize| vec![(e(h[i - 1]).powi(2) - e(h[i]).powi(2)).sqrt()];
        let skip = |i: usize| vec![(e(h[i - 2]).powi(2) - e(h[i]).powi(2)).sqrt()];
        let r: Vec<LevelResult> = (0..4)
            .map(|i| LevelResult {
                refine: i as u32,
                h: h[i],
                k: 0.1,
                increment: (i >= 1).then(|| inc(i)),
                skip: (i >= 2).then(|| skip(i)),
                jumps: vec![(0.1 * h[i]).powi(2)],
                ..LevelResult::default()
            })
            .collect();
        let est = estimate(&r);
        let m = est.model.unwrap();
        assert!((m.p - 1.0).abs() < 1e-8 && (m.beta - 1.0).abs() < 1e-6, "{m:?}");
        for (i, l) in est.levels.iter().enumerate() {
            let truth = (e(h[i]).powi(2) + (0.1 * h[i]).powi(2)).sqrt();
            assert!((l.error[0] / truth - 1.0).abs() < 1e-8 && l.verdict == Verdict::InRange, "{i}: {l:?}");
        }
    }
}

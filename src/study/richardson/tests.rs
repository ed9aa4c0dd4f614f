//! Synthetic sequences with known p, C (and β) for the Richardson/GCI functions.

use super::*;

/// Distances of the model for sizes x (coarse → fine): (a, b, D) of the three levels.
fn model_distances(x: [f64; 3], p: f64, beta: f64, c: f64) -> (f64, f64, f64) {
    let d = |i: f64, j: f64| c * j.powf(p) * phi((i / j).powf(p), beta).sqrt();
    (d(x[0], x[1]), d(x[1], x[2]), d(x[0], x[2]))
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|a| a * a).sum::<f64>().sqrt()
}

fn dist(u: &[f64], v: &[f64]) -> f64 {
    u.iter().zip(v).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt()
}

/// The fit recovers p, β, C for constant and non-constant ratios and β from 0 to 1.5.
#[test]
fn norm_model_recovers_p_beta_c() {
    for x in [[0.4, 0.2, 0.1], [0.5, 0.2, 0.125], [1.0, 0.25, 0.0625]] {
        for (p, beta) in [(1.0, 0.0), (1.0, 1.0), (0.87, 0.4), (2.0, 1.5), (0.6, 0.9)] {
            let (a, b, d) = model_distances(x, p, beta, 3.0);
            let m = NormModel::fit(x, a, b, d).expect("fit");
            assert!(
                (m.p - p).abs() < 1e-8 && (m.beta - beta).abs() < 1e-7 && (m.c - 3.0).abs() < 1e-7,
                "{x:?} {p} {beta}: {m:?}"
            );
            let (ef, ec) = m.estimate(x[1], x[2], b);
            assert!((ef / (3.0 * x[2].powf(p)) - 1.0).abs() < 1e-8 && (ec / (3.0 * x[1].powf(p)) - 1.0).abs() < 1e-8);
        }
    }
}

/// Vectors, not formulas: parallel errors e_l = C xᵖ w (backward Euler at fixed h) give β = 0 and the
/// classical estimate d/(rᵖ − 1); errors with mutually orthogonal increments (nested Galerkin) give
/// β = 1 and d/√(r^{2p} − 1).
#[test]
fn norm_model_on_vectors() {
    let x = [0.25, 0.125, 0.0625, 0.03125];
    let w = [0.3, -1.2, 0.5];
    let par: Vec<Vec<f64>> = x.iter().map(|&h| w.iter().map(|a| 2.0 * h * a).collect()).collect();
    // orthogonal increments: e_l = Σ_{k ≥ l} δ_k, δ_k = unit vector k times C √(x_k² − x_{k+1}²), tail C x_last
    let c = 2.0 * norm(&w);
    let mut orth = vec![vec![0.0; x.len()]; x.len()];
    for (l, row) in orth.iter_mut().enumerate() {
        for k in l..x.len() {
            let next = if k + 1 < x.len() { x[k + 1] } else { 0.0 };
            row[k] = c * (x[k] * x[k] - next * next).sqrt();
        }
    }
    for (e, beta, classical) in [(&par, 0.0, 1.0), (&orth, 1.0, 3f64.sqrt())] {
        let (a, b, d) = (dist(&e[1], &e[2]), dist(&e[2], &e[3]), dist(&e[1], &e[3]));
        let m = NormModel::fit([x[1], x[2], x[3]], a, b, d).unwrap();
        assert!((m.p - 1.0).abs() < 1e-8 && (m.beta - beta).abs() < 1e-6, "{m:?}");
        let (ef, _) = m.estimate(x[2], x[3], b);
        assert!((ef / norm(&e[3]) - 1.0).abs() < 1e-8);
        assert!((ef * classical / b - 1.0).abs() < 1e-8);
    }
}

/// Distances that no model reproduces are refused: equal solutions on the two finest levels (θ = frac(N/3)
/// alternating in a k study with N = 2^j), a finer distance larger than the coarser one, and D > a + b.
#[test]
fn norm_model_refuses() {
    let x = [0.25, 0.125, 0.0625];
    assert_eq!(NormModel::fit(x, 1.0, 0.0, 1.0), None);
    assert_eq!(NormModel::fit(x, 1.0, 1.5, 2.0), None);
    assert_eq!(NormModel::fit(x, 1.0, 0.5, 1.7), None);
}

/// Q = 2 − 0.3 x^{0.9}: Q* = 2 and p = 0.9 from three levels with ratios 2 and 2.5; an oscillating
/// sequence is refused.
#[test]
fn scalar_extrapolation() {
    let q = |x: f64| 2.0 - 0.3 * x.powf(0.9);
    for x in [[0.4, 0.2, 0.1], [0.5, 0.25, 0.1]] {
        let m = ScalarModel::fit(x, x.map(q)).unwrap();
        assert!((m.p - 0.9).abs() < 1e-8 && (m.limit - 2.0).abs() < 1e-9, "{m:?}");
    }
    assert_eq!(ScalarModel::fit([0.4, 0.2, 0.1], [1.0, 1.2, 1.1]), None);
}

/// An asymptotic sequence e = C x is in range at every level; a sequence whose coarsest pair converges
/// with order 0.5 is refused on the coarsest level only; with orders 0.5, 0.5, 1, 1 the only check of the
/// finest three (levels 1/2) fails, so every level is refused; an order above the theoretical one is
/// refused everywhere, and three levels cannot be checked.
#[test]
fn asymptotic_range_can_refuse() {
    let x = [0.4, 0.2, 0.1, 0.05, 0.025];
    let good: Vec<f64> = x.iter().map(|h| 3.0 * h).collect();
    assert!(asymptotic(&x, 1.0, &good, 1.0).iter().all(|v| *v == Verdict::InRange));
    // orders 0.5, 1, 1, 1 between successive levels
    let one = [
        3.0 * 0.4,
        3.0 * 0.4 / 2f64.sqrt(),
        3.0 * 0.4 / 2f64.powf(1.5),
        3.0 * 0.4 / 2f64.powf(2.5),
        3.0 * 0.4 / 2f64.powf(3.5),
    ];
    let v = asymptotic(&x, 1.0, &one, 1.0);
    assert!(matches!(v[0], Verdict::NotYet(_)), "{v:?}");
    assert!(v[1..].iter().all(|v| v.text().starts_with("in the asymptotic")), "{v:?}");
    // orders 0.5, 0.5, 1, 1
    let pre = [3.0 * 0.4, 3.0 * 0.4 / 2f64.sqrt(), 3.0 * 0.4 / 2.0, 3.0 * 0.4 / 4.0, 3.0 * 0.4 / 8.0];
    let v = asymptotic(&x, 1.0, &pre, 1.0);
    assert!(v.iter().all(|v| matches!(v, Verdict::NotYet(_))), "{v:?}");
    assert!(asymptotic(&x, 2.0, &good, 1.0).iter().all(|v| v.text().contains("outside")));
    assert!(asymptotic(&x[..3], 1.0, &good[..3], 1.0)[2].text().contains("fourth level"));
}

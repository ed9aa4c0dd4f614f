//! Observed orders of convergence: the one place they are computed in the crate.
//!
//! For errors e_a, e_b at mesh sizes (or time steps) x_a, x_b, the observed order is
//!   p = log(e_a / e_b) / log(x_a / x_b),
//! the exponent of e ≈ C xᵖ through both points; over several levels, the least-squares slope of
//! log e against log x is the fitted order.
//!
//! Without errors, from the differences of three levels x₁ > x₂ > x₃ (values Q = Q* + C xᵖ),
//! ε₂₁ = |Q₂ − Q₁| and ε₃₂ = |Q₃ − Q₂|, the order solves (Celik et al. 2008, J. Fluids Eng. 130)
//!   log(ε₂₁/ε₃₂) = p log r₃₂ + log((r₂₁ᵖ − 1)/(r₃₂ᵖ − 1)),   r₂₁ = x₁/x₂, r₃₂ = x₂/x₃,
//! which for a constant ratio r is p = log(ε₂₁/ε₃₂)/log r, and otherwise is solved by bisection (the
//! right side increases with p).
//!
//! ```
//! use tresca_cr::study::orders::{fitted_order, observed_order, order_three, successive_orders};
//!
//! // e = 3 h² on h = 1/4, 1/8, 1/16: order 2 between levels and fitted
//! let h = [0.25, 0.125, 0.0625];
//! let e: Vec<f64> = h.iter().map(|h| 3.0 * h * h).collect();
//! assert!((observed_order(e[0], e[1], h[0], h[1]) - 2.0).abs() < 1e-12);
//! assert!(successive_orders(&h, &e).iter().all(|p| (p - 2.0).abs() < 1e-12));
//! assert!((fitted_order(&h, &e) - 2.0).abs() < 1e-12);
//! // without errors: Q = 1 + h² gives the differences 3/64 and 3/256, so order 2 again
//! let q: Vec<f64> = h.iter().map(|h| 1.0 + h * h).collect();
//! let p = order_three(h, (q[1] - q[0]).abs(), (q[2] - q[1]).abs()).unwrap();
//! assert!((p - 2.0).abs() < 1e-9);
//! ```

/// p = log(e_a/e_b) / log(x_a/x_b).
pub fn observed_order(e_a: f64, e_b: f64, x_a: f64, x_b: f64) -> f64 {
    (e_a / e_b).ln() / (x_a / x_b).ln()
}

/// Observed orders between successive levels.
pub fn successive_orders(x: &[f64], e: &[f64]) -> Vec<f64> {
    (1..x.len()).map(|i| observed_order(e[i - 1], e[i], x[i - 1], x[i])).collect()
}

/// Least-squares slope of log e against log x.
pub fn fitted_order(x: &[f64], e: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let n = lx.len() as f64;
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let sxy: f64 = lx.iter().zip(&ly).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = lx.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// The order of three levels from their differences (module doc); None if no p in (0, 8] fits.
pub fn order_three(x: [f64; 3], e21: f64, e32: f64) -> Option<f64> {
    if !(x[0] > x[1] && x[1] > x[2] && x[2] > 0.0 && e21 > 0.0 && e32 > 0.0) {
        return None;
    }
    let (r21, r32) = (x[0] / x[1], x[1] / x[2]);
    if (r21 - r32).abs() <= 1e-12 * r32 {
        let p = observed_order(e21, e32, r21, 1.0);
        return (p > 0.0 && p <= 8.0).then_some(p);
    }
    let target = (e21 / e32).ln();
    let g = |p: f64| p * r32.ln() + ((r21.powf(p) - 1.0) / (r32.powf(p) - 1.0)).ln() - target;
    let (mut lo, mut hi) = (1e-9, 8.0);
    if !(g(lo) < 0.0 && g(hi) > 0.0) {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if g(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// e = 3 x² gives p = 2 for any pair of sizes; halving the error with halved x gives p = 1.
    #[test]
    fn order_of_a_power_law_is_its_exponent() {
        let e = |x: f64| 3.0 * x * x;
        assert!((observed_order(e(0.3), e(0.07), 0.3, 0.07) - 2.0).abs() < 1e-13);
        assert!((observed_order(2.0, 1.0, 0.5, 0.25) - 1.0).abs() < 1e-15);
        let x = [0.4, 0.2, 0.1, 0.05];
        let ex: Vec<f64> = x.iter().map(|&v| e(v)).collect();
        assert!((fitted_order(&x, &ex) - 2.0).abs() < 1e-13);
        assert!(successive_orders(&x, &ex).iter().all(|p| (p - 2.0).abs() < 1e-13));
    }

    /// Q = 1 + 0.7 x^1.3 on x = 0.3, 0.2, 0.07 (ratios 1.5 and 2.86) and on x = 0.4, 0.2, 0.1.
    #[test]
    fn order_of_three_levels_with_any_ratios() {
        let q = |x: f64| 1.0 + 0.7 * x.powf(1.3);
        for x in [[0.3, 0.2, 0.07], [0.4, 0.2, 0.1]] {
            let p = order_three(x, (q(x[1]) - q(x[0])).abs(), (q(x[2]) - q(x[1])).abs()).unwrap();
            assert!((p - 1.3).abs() < 1e-9, "{x:?}: {p}");
        }
        // no convergence: the finer difference is the larger one
        assert_eq!(order_three([0.4, 0.2, 0.1], 1.0, 2.0), None);
    }
}

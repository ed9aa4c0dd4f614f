//! Observed orders of convergence: the one place they are computed in the crate.
//!
//! For errors e_a, e_b at mesh sizes (or time steps) x_a, x_b, the observed order is
//!   p = log(e_a / e_b) / log(x_a / x_b),
//! the exponent of e ≈ C xᵖ through both points; over several levels, the least-squares slope of
//! log e against log x is the fitted order.

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
}

//! Observed orders of convergence: the one place they are computed in the crate.
//!
//! For errors e_a, e_b at mesh sizes (or time steps) x_a, x_b, the observed order is
//!   p = log(e_a / e_b) / log(x_a / x_b),
//! the exponent of e ≈ C xᵖ through both points.

/// p = log(e_a/e_b) / log(x_a/x_b).
pub fn observed_order(e_a: f64, e_b: f64, x_a: f64, x_b: f64) -> f64 {
    (e_a / e_b).ln() / (x_a / x_b).ln()
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
    }
}

//! The spatial error as a smooth part and a singular part, from the ratios of the space pilot's increments.
//!
//! Where the scene allows an order α = min(1, α_min) < 1 but the pilot shows CR's order 1 (a solution whose
//! singular coefficient at the corners is small or zero: a manufactured solution that is smooth there), the
//! leading terms of the error are e_h² = G² h² + S² h^{2α}: the smooth part of CR's error, and the
//! singular function's share, orthogonal to it to leading order (Galerkin orthogonality of nested levels,
//! as for the increments). With the level ratio r (h_{j−1} = r h_j), the increments d_j² = e_{j−1}² − e_j²
//! of two successive pairs of levels give, in units of level j (q_j = S_j²/G_j²),
//!
//!   d_j² = (r² − 1) G_j² + (r^{2α} − 1) S_j²,   d_{j−1}² = r²(r² − 1) G_j² + r^{2α}(r^{2α} − 1) S_j²,
//!
//! so with ρ = d_{j−1}/d_j:   q_j = (r² − 1)(ρ² − r²) / ((r^{2α} − 1)(r^{2α} − ρ²)),
//!
//! 0 where ρ ≥ r (order 1 or above: no singular part seen), unbounded where ρ ≤ r^α (all singular: the
//! bound of `plan::pilot`). The ratio is given the benefit of the pilots' scatter in order ([`ORDER_SCATTER`],
//! ρ r^0.05: an order deficit of 0.012 would otherwise read as a singular part of a third of the error, the
//! formula amplifying the deficit about 7.5 times), and the smooth part takes the observed order p ≤ 1 in
//! place of 1 (r^{2p} for r²), as the plans did before the order bound. The share grows as h → 0 like h^{2α−2}: q at the finest level L is
//! q_j (h_j/h_L)^{2−2α}. The split takes the largest of the last two pairs' shares at level L (the more
//! singular reading of the two) and the finest level's estimated error E: G = E/√(1 + q), S = E√(q/(1 + q)).
//! The prediction then decays like h where the smooth part dominates and like h^α where the singular one
//! does. It is the asymptotic expansion fitted to the pilot, not a bound: `plan::pilot` uses it only where
//! the observed order is above α and not falling, and the estimates are consistent.

/// The energy-norm order in h of the lowest-order CR element on a smooth solution.
pub const OPTIMAL_ORDER: f64 = 1.0;
/// The scatter of a fitted space order over the pilots' few levels (the planner's in-range band): a pilot
/// whose order is at least OPTIMAL_ORDER − ORDER_SCATTER shows the smooth part in its asymptotic range,
/// which the split needs (`plan::pilot` splits only then).
pub const ORDER_SCATTER: f64 = 0.05;

/// [smooth, singular] parts of the finest level's error `error` (module doc), from the level sizes `x`
/// (coarse → fine) and the increments `d` (`d[j]` between levels j − 1 and j), with the smooth part of
/// order `smooth` ≤ 1 in place of 1 and each increment ratio given the benefit of `scatter` in its order
/// (ρ r^scatter: a ratio within the pilots' scatter of the smooth order shows no singular part); `None`
/// when α ≥ `smooth` (one order) or fewer than three increments.
pub fn split(x: &[f64], d: &[f64], error: f64, (alpha, smooth, scatter): (f64, f64, f64)) -> Option<[f64; 2]> {
    let n = x.len();
    if alpha >= smooth - 1e-9 || n < 4 || d.len() != n {
        return None;
    }
    let share = |j: usize| -> f64 {
        let r = x[j - 1] / x[j];
        let (r2, r2a) = (r.powf(2.0 * smooth), r.powf(2.0 * alpha));
        let rho2 = (d[j - 1] / d[j] * r.powf(scatter)).powi(2);
        let q = if !(d[j] > 0.0 && d[j - 1] > 0.0) || rho2 <= r2a {
            f64::INFINITY
        } else if rho2 >= r2 {
            0.0
        } else {
            (r2 - 1.0) * (rho2 - r2) / ((r2a - 1.0) * (r2a - rho2))
        };
        q * (x[j] / x[n - 1]).powf(2.0 * smooth - 2.0 * alpha)
    };
    let q = share(n - 1).max(share(n - 2));
    Some(if q.is_finite() { [error / (1.0 + q).sqrt(), error * (q / (1.0 + q)).sqrt()] } else { [0.0, error] })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Errors made of the two terms exactly: the split gives the finest level's two parts back; a pure
    /// order-1 sequence has no singular part, a pure order-α one no smooth part.
    #[test]
    fn split_recovers_the_two_parts() {
        let alpha = 0.7112;
        let x: Vec<f64> = (0..4).map(|k| 0.5f64.powi(k)).collect();
        for (g, s) in [(1.0, 0.3), (1.0, 0.0), (0.0, 1.0), (0.2, 1.0)] {
            let e2 = |h: f64| (g * h).powi(2) + (s * h.powf(alpha)).powi(2);
            let d: Vec<f64> = (0..4).map(|j| if j == 0 { 0.0 } else { (e2(x[j - 1]) - e2(x[j])).sqrt() }).collect();
            let [gs, ss] = split(&x, &d, e2(x[3]).sqrt(), (alpha, 1.0, 0.0)).unwrap();
            assert!((gs - g * x[3]).abs() < 1e-12 && (ss - s * x[3].powf(alpha)).abs() < 1e-12, "{g} {s}: {gs} {ss}");
        }
        assert_eq!(split(&x, &[0.0, 1.0, 0.5, 0.25], 0.25, (1.0, 1.0, 0.0)), None);
        // increments of order 0.97 lie within a scatter of 0.05 of order 1: no singular part; without the
        // scatter they show one
        let d: Vec<f64> = (0..4).map(|j| 2f64.powf(-0.97 * j as f64)).collect();
        assert_eq!(split(&x, &d, 1.0, (alpha, 1.0, 0.05)).unwrap()[1], 0.0);
        assert!(split(&x, &d, 1.0, (alpha, 1.0, 0.0)).unwrap()[1] > 0.1);
    }
}

//! Quadrature rules as data.
//!
//! * Triangle: the 6-point degree-4 Dunavant rule, in barycentric coordinates with weights summing to 1
//!   (multiply by |T|). Used for body forces and for error norms.
//! * Edge: 2-point Gauss (exact for the stabilisation: products of two P1 traces) and 3-point Gauss
//!   (degree 5; Neumann loads, edge means of g_a and of u₀), on the parameter s ∈ [0, 1], weights summing to 1.
//!
//! ```
//! use tresca_cr::fem::quadrature::{tri_point, GAUSS2, TRI4};
//!
//! // Dunavant 4 integrates x²y² over the unit triangle exactly: 2!·2!/6! = 1/180
//! let tri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
//! let area = 0.5;
//! let i: f64 = TRI4.iter().map(|&(l, w)| { let p = tri_point(tri, l); w * area * p[0] * p[0] * p[1] * p[1] }).sum();
//! assert!((i - 1.0 / 180.0).abs() < 1e-15);
//! // 2-point Gauss is exact for cubics on [0, 1]
//! let c: f64 = GAUSS2.iter().map(|&(s, w)| w * s * s * s).sum();
//! assert!((c - 0.25).abs() < 1e-15);
//! ```

/// Dunavant degree 4: (barycentric coordinates, weight).
#[allow(clippy::excessive_precision)] // the rule's published 18 digits, kept to compare with the table; they round to the same f64
pub const TRI4: [([f64; 3], f64); 6] = {
    const A: f64 = 0.445_948_490_915_964_886;
    const WA: f64 = 0.223_381_589_678_011_466;
    const B: f64 = 0.091_576_213_509_770_743;
    const WB: f64 = 0.109_951_743_655_321_867;
    [
        ([A, A, 1.0 - 2.0 * A], WA),
        ([A, 1.0 - 2.0 * A, A], WA),
        ([1.0 - 2.0 * A, A, A], WA),
        ([B, B, 1.0 - 2.0 * B], WB),
        ([B, 1.0 - 2.0 * B, B], WB),
        ([1.0 - 2.0 * B, B, B], WB),
    ]
};

/// 2-point Gauss–Legendre on [0, 1]: (s, weight).
pub const GAUSS2: [(f64, f64); 2] = {
    #[allow(clippy::excessive_precision)] // 18 digits of 1/(2√3); they round to the same f64
    const D: f64 = 0.288_675_134_594_812_882; // 1/(2√3)
    [(0.5 - D, 0.5), (0.5 + D, 0.5)]
};

/// 3-point Gauss–Legendre on [0, 1]: (s, weight).
pub const GAUSS3: [(f64, f64); 3] = {
    #[allow(clippy::excessive_precision)] // 18 digits of √(3/5)/2; they round to the same f64
    const D: f64 = 0.387_298_334_620_741_689; // √(3/5)/2
    [(0.5 - D, 5.0 / 18.0), (0.5, 8.0 / 18.0), (0.5 + D, 5.0 / 18.0)]
};

/// Point of the triangle (a, b, c) with barycentric coordinates l.
pub fn tri_point(p: [[f64; 2]; 3], l: [f64; 3]) -> [f64; 2] {
    [l[0] * p[0][0] + l[1] * p[1][0] + l[2] * p[2][0], l[0] * p[0][1] + l[1] * p[1][1] + l[2] * p[2][1]]
}

/// Point a + s (b − a).
pub fn edge_point(a: [f64; 2], b: [f64; 2], s: f64) -> [f64; 2] {
    [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫_T λ1^i λ2^j λ3^k = 2|T| i! j! k! / (i+j+k+2)!
    fn exact(i: u32, j: u32, k: u32) -> f64 {
        let f = |n: u32| (1..=n).map(f64::from).product::<f64>();
        2.0 * f(i) * f(j) * f(k) / f(i + j + k + 2)
    }

    #[test]
    fn triangle_rule_is_exact_to_degree_4_and_not_5() {
        for d in 0..=5u32 {
            for i in 0..=d {
                for j in 0..=d - i {
                    let k = d - i - j;
                    let q: f64 = TRI4
                        .iter()
                        .map(|(l, w)| w * l[0].powi(i as i32) * l[1].powi(j as i32) * l[2].powi(k as i32))
                        .sum();
                    let err = (q - exact(i, j, k)).abs();
                    if d <= 4 {
                        assert!(err < 1e-15, "degree {d}: {i} {j} {k}: {err}");
                    }
                }
            }
        }
        let q5: f64 = TRI4.iter().map(|(l, w)| w * l[0].powi(5)).sum();
        assert!((q5 - exact(5, 0, 0)).abs() > 1e-6);
    }

    #[test]
    fn edge_rules_exact_degrees() {
        for p in 0..=5 {
            let ex = 1.0 / (p as f64 + 1.0);
            let q3: f64 = GAUSS3.iter().map(|(s, w)| w * s.powi(p)).sum();
            assert!((q3 - ex).abs() < 1e-15, "gauss3 degree {p}");
            let q2: f64 = GAUSS2.iter().map(|(s, w)| w * s.powi(p)).sum();
            if p <= 3 {
                assert!((q2 - ex).abs() < 1e-15, "gauss2 degree {p}");
            }
        }
    }
}

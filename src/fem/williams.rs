//! The leading singular exponent of plane-strain elasticity at a wedge (Williams 1952; the mixed pairs as in
//! Rössle 2000).
//!
//! Near a boundary point where the polygon has the interior angle ω, or where the boundary condition
//! changes type, the displacement behaves like u ~ r^α Φ(θ) in polar coordinates (r, θ), 0 < θ < ω, for
//! the smallest Re α > 0 among the nontrivial solutions of the homogeneous problem. Williams' Airy stress
//! function Φ = r^{α+1} F(θ), F = a₁ cos((α+1)θ) + a₂ sin((α+1)θ) + a₃ cos((α−1)θ) + a₄ sin((α−1)θ),
//! gives (plane strain, κ = 3 − 4ν)
//!
//! - σ_θθ = α(α+1) r^{α−1} F, σ_rθ = −α r^{α−1} F';
//! - 2μ u_r = r^α [−(α+1)(a₁ cos + a₂ sin)((α+1)θ) + (κ−α)(a₃ cos + a₄ sin)((α−1)θ)];
//! - 2μ u_θ = r^α [(α+1)(a₁ sin − a₂ cos)((α+1)θ) + (κ+α)(a₃ sin − a₄ cos)((α−1)θ)].
//!
//! Each side imposes two rows on (a₁, …, a₄): free (σ_θθ = σ_rθ = 0: F = F' = 0), clamped (u_r = u_θ = 0)
//! or sliding (u·n = u_θ = 0 and σ_rθ = 0: a symmetry plane, a frictionless or slipping contact). The
//! exponents are the roots α of D(α) = det M(α), an entire function; they may be complex (the clamped–free
//! pair gives α = ½ ± i ln κ / 2π on a straight boundary). D has a spurious zero at α = 1, where the a₃, a₄
//! functions degenerate, so only roots with 0 < Re α < 1 are sought: they are the ones that limit an
//! approximation's order, min(1, Re α) in h for the energy norm under uniform refinement.
//!
//! The roots are found by complex Newton iterations started on a grid of the strip 0 < Re α ≤ 1,
//! 0 ≤ Im α ≤ 1.5, and kept where |D| vanishes to rounding.
//!
//! ```
//! use tresca_cr::fem::williams::{leading_exponent, Side};
//! // the L-shape's re-entrant corner (ω = 3π/2), both sides traction free
//! let a = leading_exponent([Side::Free, Side::Free], 1.5 * std::f64::consts::PI, 0.3).unwrap();
//! assert!((a.re - 0.544484).abs() < 1e-6 && a.im == 0.0);
//! // a convex right angle, both sides free: no singular exponent below 1
//! assert!(leading_exponent([Side::Free, Side::Free], std::f64::consts::FRAC_PI_2, 0.3).is_none());
//! ```

use nalgebra::{Complex, Matrix4};

type C = Complex<f64>;

/// The condition on one side of a wedge, for the homogeneous problem.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Side {
    /// Traction free (Neumann).
    Free,
    /// u = 0 (Dirichlet; a sticking contact).
    Clamped,
    /// u·n = 0 and zero tangential traction (symmetry; a slipping or frictionless contact).
    Sliding,
}

impl Side {
    /// The name used in messages.
    pub fn name(self) -> &'static str {
        match self {
            Side::Free => "free",
            Side::Clamped => "clamped",
            Side::Sliding => "sliding",
        }
    }
}

/// The two rows a side at angle θ imposes on (a₁, a₂, a₃, a₄).
fn rows(side: Side, alpha: C, theta: f64, kappa: f64) -> [[C; 4]; 2] {
    let (a, b) = (alpha + 1.0, alpha - 1.0);
    let (c1, s1) = ((a * theta).cos(), (a * theta).sin());
    let (c2, s2) = ((b * theta).cos(), (b * theta).sin());
    let f = [c1, s1, c2, s2];
    let df = [-a * s1, a * c1, -b * s2, b * c2];
    let ur = [-a * c1, -a * s1, (kappa - alpha) * c2, (kappa - alpha) * s2];
    let ut = [a * s1, -a * c1, (kappa + alpha) * s2, -(kappa + alpha) * c2];
    match side {
        Side::Free => [f, df],
        Side::Clamped => [ur, ut],
        Side::Sliding => [ut, df],
    }
}

/// D(α) = det M(α) for sides `sides[0]` at θ = 0 and `sides[1]` at θ = ω.
fn det(sides: [Side; 2], alpha: C, omega: f64, kappa: f64) -> C {
    let [r0, r1] = rows(sides[0], alpha, 0.0, kappa);
    let [r2, r3] = rows(sides[1], alpha, omega, kappa);
    Matrix4::from_fn(|i, j| [r0, r1, r2, r3][i][j]).determinant()
}

/// Newton's iteration for D from `z`, with a central-difference derivative; the root, if it converged.
fn newton(sides: [Side; 2], mut z: C, omega: f64, kappa: f64) -> Option<C> {
    const H: f64 = 1e-7; // difference step: D is entire, so its O(H²) error is far below the root's tolerance
    for _ in 0..60 {
        let d = (det(sides, z + H, omega, kappa) - det(sides, z - H, omega, kappa)) / (2.0 * H);
        if d.norm() == 0.0 || !d.is_finite() {
            return None;
        }
        let step = det(sides, z, omega, kappa) / d;
        z -= step;
        if step.norm() < 1e-13 {
            return Some(z);
        }
    }
    None
}

/// The exponent α with the smallest real part in 0 < Re α < 1 (taken with Im α ≥ 0), or `None` when the
/// wedge has none: the solution is then as smooth as a first-order method needs. `omega` in (0, 2π].
pub fn leading_exponent(sides: [Side; 2], omega: f64, nu: f64) -> Option<C> {
    let kappa = 3.0 - 4.0 * nu;
    // |D| at a root, relative to the size of M's entries (≤ about 4 here): rounding of a 4×4 determinant
    let scale = (1.0 + kappa).powi(4);
    let mut best: Option<C> = None;
    for i in 1..=50 {
        for j in 0..16 {
            let start = C::new(0.02 * f64::from(i), 0.1 * f64::from(j));
            let Some(z) = newton(sides, start, omega, kappa) else { continue };
            let z = C::new(z.re, z.im.abs());
            let converged = det(sides, z, omega, kappa).norm() <= 1e-10 * scale;
            if converged && z.re > 1e-6 && z.re < 1.0 - 1e-7 && best.is_none_or(|b| z.re < b.re - 1e-9) {
                best = Some(if z.im < 1e-9 { C::new(z.re, 0.0) } else { z });
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn re(sides: [Side; 2], omega: f64, nu: f64) -> f64 {
        leading_exponent(sides, omega, nu).map_or(f64::INFINITY, |a| a.re)
    }

    /// The published roots, to the digits published (hence the tolerances of half a unit in the last).
    #[test]
    fn the_published_roots() {
        use Side::*;
        // L-shape (ω = 3π/2), free–free: 0.5445 (Williams; Grisvard's table)
        assert!((re([Free, Free], 1.5 * PI, 0.3) - 0.5445).abs() < 5e-5);
        // the crack (ω = 2π): free–free and clamped–clamped ½ for every ν, sliding–sliding ½
        for nu in [0.0, 0.3, 0.49] {
            assert!((re([Free, Free], 2.0 * PI, nu) - 0.5).abs() < 1e-9);
            assert!((re([Clamped, Clamped], 2.0 * PI, nu) - 0.5).abs() < 1e-9);
        }
        assert!((re([Sliding, Sliding], 2.0 * PI, 0.3) - 0.5).abs() < 1e-9);
        // the crack, clamped–free: ¼ ± i ln κ / 4π; a straight boundary, clamped–free: ½ ± i ln κ / 2π
        let kappa: f64 = 3.0 - 4.0 * 0.3;
        let a = leading_exponent([Clamped, Free], 2.0 * PI, 0.3).unwrap();
        assert!((a.re - 0.25).abs() < 1e-9 && (a.im - kappa.ln() / (4.0 * PI)).abs() < 1e-9);
        let a = leading_exponent([Clamped, Free], PI, 0.3).unwrap();
        assert!((a.re - 0.5).abs() < 1e-9 && (a.im - kappa.ln() / (2.0 * PI)).abs() < 1e-9);
    }

    /// A sliding side is a symmetry plane: the wedge ω with a sliding side is half of the wedge 2ω.
    #[test]
    fn a_sliding_side_halves_the_symmetric_wedge() {
        use Side::*;
        for omega in [0.6 * PI, 0.75 * PI, PI] {
            let half = re([Sliding, Free], omega, 0.3);
            assert!((half - re([Free, Free], 2.0 * omega, 0.3)).abs() < 1e-9, "ω = {omega}");
        }
    }

    /// The order of the sides does not matter, and smooth straight boundaries have no exponent below 1.
    #[test]
    fn symmetric_in_the_sides_and_none_on_a_straight_uniform_side() {
        use Side::*;
        for (a, b) in [(Clamped, Free), (Sliding, Free), (Clamped, Sliding)] {
            let (x, y) = (re([a, b], 1.3 * PI, 0.25), re([b, a], 1.3 * PI, 0.25));
            assert!((x - y).abs() < 1e-9 || (x.is_infinite() && y.is_infinite()));
        }
        for s in [Free, Clamped, Sliding] {
            assert!(leading_exponent([s, s], PI, 0.3).is_none(), "{s:?}");
        }
    }
}

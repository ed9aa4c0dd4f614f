//! Richardson extrapolation and Roache's grid convergence index (GCI) without an exact solution: pure
//! functions of the level sizes x (h, or k when only the time step changes; coarse → fine) and of what
//! the levels give.
//!
//! **Scalars** Q_l (an output such as the maximum slip): Q_l = Q* + C x_lᵖ. From the three finest levels
//! 1, 2, 3 (coarse → fine), ε₂₁ = Q₂ − Q₁, ε₃₂ = Q₃ − Q₂ of one sign (monotone convergence), p solves
//! ε₂₁/ε₃₂ = (r₃₂ᵖ (r₂₁ᵖ − 1))/(r₃₂ᵖ − 1) with r₂₁ = x₁/x₂, r₃₂ = x₂/x₃ ([`orders::order_three`]), and
//!   Q* = Q₃ + ε₃₂/(r₃₂ᵖ − 1),   estimated error of level l: |Q_l − Q*|,
//!   GCI_l = F_s |Q_l − Q*| (F_s = 1.25 with three levels, 3 with two, Roache).
//!
//! **Norms** (the energy error |||u − u_l|||, u unknown): only distances between levels are computable.
//! Model: the errors e_l = u_l − u have |e_l| = C x_lᵖ and, for x_j ≤ x_i, inner products
//!   ⟨e_i, e_j⟩ = C² x_i^{p(1−β)} x_j^{p(1+β)},  so  |u_i − u_j|² = C² x_j^{2p} φ((x_i/x_j)ᵖ, β),  φ(X, β) = X² + 1 − 2X^{1−β}.
//! β = 0 is classical Richardson (errors parallel, one error shape scaled by xᵖ: backward Euler's
//! O(k) error at fixed h is θkW); β = 1 is Galerkin orthogonality on nested spaces
//! (|e_i|² = |e_j|² + |u_i − u_j|²: the CR gradient is the elementwise mean of ∇u to leading order, and
//! elementwise means on nested meshes are orthogonal increments). The three distances a = |u₁ − u₂|,
//! b = |u₂ − u₃|, D = |u₁ − u₃| of the three finest levels fix C, p and β ([`NormModel::fit`]); for a
//! constant ratio r, a/b = rᵖ and D²/b² = φ(r^{2p}, β)/φ(rᵖ, β). The error of level j is then estimated
//! from its distance d to the next coarser level i: E_j = d/√φ((x_i/x_j)ᵖ, β), and E_i = E_j (x_i/x_j)ᵖ.
//! Neither p nor β is fitted to an error: both come from distances between computed solutions.
//!
//! **Asymptotic range** ([`asymptotic`]): the GCI ratio GCI_{l−1}/GCI_l of two levels, at least one of
//! them estimated from data outside the three-level fit, must equal (x_{l−1}/x_l)ᵖ to within
//! [`RATIO_TOL`] (so four levels are needed for any level to be called asymptotic), and p must lie in
//! [p_th/2, p_th + [`ORDER_TOL`]]: below the theoretical order (singularities lower it, down to 1/2
//! for the energy norm at a crack tip in 2D) but not above it.

use super::orders::{observed_order, order_three};

/// Roache's safety factor with three or more levels (an observed order).
pub const FS_THREE: f64 = 1.25;
/// Roache's safety factor with two levels (the order assumed, not observed).
pub const FS_TWO: f64 = 3.0;
/// |GCI_{l−1}/(rᵖ GCI_l) − 1| allowed: a mismatch δ in the ratio is an order error δ/ln r, which moves the
/// classical (β = 0) estimate d/(rᵖ − 1) by rᵖ/(rᵖ − 1)·δ — 2δ for r = 2, p = 1 (less for β = 1): 0.1
/// keeps that within the ±20 % band the estimates are held to.
pub const RATIO_TOL: f64 = 0.1;
/// p may exceed the theoretical order by this much (the same order error budget as [`RATIO_TOL`] for r = 2:
/// ln(1.1)/ln 2 ≈ 0.14, rounded to 0.15) before the sequence is called pre-asymptotic.
pub const ORDER_TOL: f64 = 0.15;

/// φ(X, β) = X² + 1 − 2X^{1−β}: |u_i − u_j|²/(C² x_j^{2p}) with X = (x_i/x_j)ᵖ.
fn phi(x: f64, beta: f64) -> f64 {
    x * x + 1.0 - 2.0 * x.powf(1.0 - beta)
}

/// The norm model |e_l| = C x_lᵖ with correlation exponent β (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormModel {
    pub p: f64,
    pub beta: f64,
    pub c: f64,
}

/// Bisection for a root of f on [lo, hi] (f(lo), f(hi) of opposite signs), else None.
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> Option<f64> {
    let (mut flo, fhi) = (f(lo), f(hi));
    if !(flo.is_finite() && fhi.is_finite()) || flo * fhi > 0.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let fm = f(mid);
        if fm == 0.0 {
            return Some(mid);
        }
        if (fm < 0.0) == (flo < 0.0) {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Largest order and β searched: beyond these a sequence is not a power law worth extrapolating.
const P_MAX: f64 = 8.0;
const BETA_MAX: f64 = 4.0;

impl NormModel {
    /// Fit to sizes x = [x₁, x₂, x₃] (coarse → fine, decreasing) and distances a = |u₁ − u₂|,
    /// b = |u₂ − u₃|, dd = |u₁ − u₃|. None when no (p, β) ∈ (0, 8] × [0, 4] reproduces them.
    pub fn fit(x: [f64; 3], a: f64, b: f64, dd: f64) -> Option<NormModel> {
        if !(x[0] > x[1] && x[1] > x[2] && x[2] > 0.0 && a > 0.0 && b > 0.0 && dd > 0.0) {
            return None;
        }
        let (l21, l32) = ((x[0] / x[1]).ln(), (x[1] / x[2]).ln());
        // for given β, p from log(a²/b²) = 2p ln r₃₂ + ln φ(r₂₁ᵖ, β) − ln φ(r₃₂ᵖ, β)
        let p_of = |beta: f64| {
            let g = |p: f64| {
                2.0 * p * l32 + phi((p * l21).exp(), beta).ln() - phi((p * l32).exp(), beta).ln() - 2.0 * (a / b).ln()
            };
            bisect(g, 1e-6, P_MAX)
        };
        // then β from log(D²/b²) = ln φ((x₁/x₃)ᵖ, β) − ln φ(r₃₂ᵖ, β), decreasing in β
        let resid = |beta: f64| -> f64 {
            match p_of(beta) {
                Some(p) => {
                    phi((p * (l21 + l32)).exp(), beta).ln() - phi((p * l32).exp(), beta).ln() - 2.0 * (dd / b).ln()
                }
                None => f64::NAN,
            }
        };
        let beta = match bisect(resid, 0.0, BETA_MAX) {
            Some(bt) => bt,
            // D = a + b to rounding: exactly parallel errors (β = 0)
            None if (dd - (a + b)).abs() <= 1e-9 * dd => 0.0,
            None => return None,
        };
        let p = p_of(beta)?;
        let c = b / (x[2].powf(p) * phi((p * l32).exp(), beta).sqrt());
        c.is_finite().then_some(NormModel { p, beta, c })
    }

    /// (E_fine, E_coarse) from the distance d between a coarse level of size xc and a fine one of size xf.
    pub fn estimate(&self, xc: f64, xf: f64, d: f64) -> (f64, f64) {
        let big = (xc / xf).powf(self.p);
        let ef = d / phi(big, self.beta).sqrt();
        (ef, ef * big)
    }
}

/// The scalar extrapolation of the three finest levels (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalarModel {
    pub p: f64,
    /// The extrapolated value Q*.
    pub limit: f64,
}

impl ScalarModel {
    /// Fit to sizes x (coarse → fine) and values q of three levels; None unless the differences have
    /// one sign (monotone convergence) and an order in (0, 8] reproduces them.
    pub fn fit(x: [f64; 3], q: [f64; 3]) -> Option<ScalarModel> {
        let (e21, e32) = (q[1] - q[0], q[2] - q[1]);
        if (e21 * e32).partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            return None;
        }
        let p = order_three(x, e21.abs(), e32.abs())?;
        let r32 = x[1] / x[2];
        Some(ScalarModel { p, limit: q[2] + e32 / (r32.powf(p) - 1.0) })
    }
}

/// The asymptotic-range verdict of one level.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    InRange,
    NotYet(String),
}

impl Verdict {
    pub fn text(&self) -> String {
        match self {
            Verdict::InRange => "in the asymptotic range".into(),
            Verdict::NotYet(why) => format!("not yet: refine further ({why})"),
        }
    }
}

/// Verdict per level (coarse → fine) given the sizes x, the order p of the three finest levels, the
/// level estimates est and the theoretical order p_th.
///
/// The three finest levels' estimates come from the fit itself, so their GCI ratios equal rᵖ by
/// construction; the tests that can refuse are j = 1..=m, m = n−3, comparing levels j−1 and j (at least
/// one of them estimated from data outside the fit). Level l is in the asymptotic range when
/// p ∈ [p_th/2, p_th + ORDER_TOL] and every test j ∈ [min(l+1, m), m] passes (the test of level l with its
/// finer neighbour and all finer ones; the levels of the fit need test m); with three levels there is no
/// test and no level is called asymptotic.
pub fn asymptotic(x: &[f64], p: f64, est: &[f64], p_th: f64) -> Vec<Verdict> {
    let n = x.len();
    if !(p >= 0.5 * p_th && p <= p_th + ORDER_TOL) {
        let why = format!(
            "observed order {p:.3} outside [{:.2}, {:.2}] around the theoretical {p_th}",
            0.5 * p_th,
            p_th + ORDER_TOL
        );
        return vec![Verdict::NotYet(why); n];
    }
    if n < 4 {
        return vec![Verdict::NotYet("a fourth level is needed to check the GCI ratio".into()); n];
    }
    let m = n - 3;
    (0..n)
        .map(|l| {
            let bad: Vec<String> = ((l + 1).min(m)..=m)
                .filter_map(|j| {
                    let q = (est[j - 1] / est[j]) / (x[j - 1] / x[j]).powf(p);
                    ((q - 1.0).abs() > RATIO_TOL || !q.is_finite()).then(|| {
                        let qo = observed_order(est[j - 1], est[j], x[j - 1], x[j]);
                        format!("GCI ratio of levels {}/{} is {q:.3}·r^p: order {qo:.3} there, p = {p:.3}", j - 1, j)
                    })
                })
                .collect();
            if bad.is_empty() {
                Verdict::InRange
            } else {
                Verdict::NotYet(bad.join("; "))
            }
        })
        .collect()
}

#[cfg(test)]
mod tests;

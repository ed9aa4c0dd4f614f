//! The planner's two models, fitted to its pilot runs ([`super::pilot`]).
//!
//! **Error.** e(h, k) = e_h ⊕ e_k with e_h = C_h hᵖ (the spatial error, from a sequence of meshes at a
//! fixed time grid) and e_k = C_k k^q (the time error, from a sequence of time grids on one mesh); p and q
//! are the orders the sequences show ([`super::super::study::richardson`]), C_h and C_k are fixed by the
//! estimated error of each sequence's finest level. The two parts combine as
//!   e = √(e_h² + e_k²)   when they are orthogonal in the energy inner product, else   e = e_h + e_k.
//! Orthogonal: the spatial error of CR is a_h-orthogonal to V_h to leading order (Galerkin orthogonality
//! on nested meshes; the study measures it as the correlation exponent β ≈ 1), while the time error of
//! backward Euler is a smooth field (θkW for a slip that stops inside a step) that V_h resolves; the sum
//! is the triangle inequality, used for scalar outputs and whenever β < ½.
//!
//! **Cost.** wall(n, N) = S(n) + N s(n) for n unknowns and N steps, S the set-up (assembly, the one
//! factorisation, condensation) and s the cost of a step (load, one triangular-solve pair, the friction
//! solve). S = c_S n^a, its exponent a from the two finest space pilot levels where both set-ups are long
//! enough to be timed ([`MEASURABLE_SETUP`]), else the least growth [`SETUP_EXPONENT`]`.0`, clamped to what
//! the algorithms do at the plans' sizes: between n^1.2 (measured) and O(n^1.5) (sparse Cholesky of a 2D
//! mesh). s = c n ln n, the cost of the triangular solves with a fill-reducing factor of a 2D mesh (the
//! friction work, O(n_c²) per iteration with n_c ∝ √n under uniform refinement, is smaller), from the time
//! pilot's levels with at least half the most steps: per-step costs measured over a few steps are dominated
//! by the first steps' extra Newton iterations and by start-up.
//!
//! **Why minima.** Each sample gives the constant it implies, c_S = S/n^a or c = s/(n ln n), and the model
//! takes the smallest over the samples that measure it (the two finest space levels; the longest time
//! levels). Everything that separates a pilot's time from the model only adds to it: the fixed overheads of
//! a small level (its set-up grows like n^0.8–1.0 there), the first steps' extra iterations, and the
//! machine's noise (a process descheduled, caches shared with other processes: milliseconds scatter 1.5×
//! between passes even on a quiet machine). So every implied constant is an upper bound of the plan's, and
//! the smallest is the tightest; a single slow sample no longer moves the prediction. An exponent fitted
//! through two millisecond set-ups amplified that noise (a 1.3× slow finest level raised it by 0.19, 1.7×
//! after two levels of extrapolation); below [`MEASURABLE_SETUP`] it is not fitted.

/// y = c xᵖ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PowerLaw {
    pub c: f64,
    pub p: f64,
}

impl PowerLaw {
    /// The law of exponent p through (x, y).
    pub fn through(x: f64, y: f64, p: f64) -> PowerLaw {
        PowerLaw { c: y / x.powf(p), p }
    }

    pub fn at(&self, x: f64) -> f64 {
        self.c * x.powf(self.p)
    }

    /// The x at which the law reaches y (x = (y/c)^{1/p}).
    pub fn solve(&self, y: f64) -> f64 {
        (y / self.c).powf(1.0 / self.p)
    }
}

/// How the spatial and the time error add up (module doc).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    Quadrature,
    Sum,
}

/// The correlation exponent from which the spatial error is taken as orthogonal to the time error.
pub const ORTHOGONAL_BETA: f64 = 0.5;

/// The time error e_k: a power law observed on the time pilot, or, when the pilot shows no regular
/// order, a bound from its distances (for every k up to the pilot's coarsest step).
///
/// The bound: if e_k(N) does not grow as N grows and decreases at least like k^{1/2} (the lowest order
/// the asymptotic check accepts), the distance between the coarsest and the finest of m + 1 levels with
/// ratio r is at least e_k(N₀)(1 − r^{−m/2}), so e_k(N) ≤ e_k(N₀) ≤ Σⱼ dⱼ/(1 − r^{−m/2}) for N ≥ N₀
/// (dⱼ: the distances of successive levels, whose sum bounds that of the extremes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeError {
    Law(PowerLaw),
    Bound(f64),
}

impl TimeError {
    /// The bound of a sequence of `levels` time levels with ratio `ratio` and successive distances
    /// summing to `sum` (the enum's doc).
    pub fn bound(sum: f64, ratio: f64, levels: usize) -> TimeError {
        let m = levels.saturating_sub(1) as f64;
        TimeError::Bound(if m > 0.0 { sum / (1.0 - ratio.powf(-0.5 * m)) } else { f64::INFINITY })
    }

    pub fn at(&self, k: f64) -> f64 {
        match self {
            TimeError::Law(l) => l.at(k),
            TimeError::Bound(b) => *b,
        }
    }
}

/// e(h, k) = e_h ⊕ e_k (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorModel {
    /// C_h hᵖ; with `singular`, the smooth part of the spatial error (p = 1).
    pub space: PowerLaw,
    /// The singular part C_s h^α of a two-term spatial error, e_h = √((C_h h)² + (C_s h^α)²)
    /// (`plan::pilot::fit`, `two_term`), α = min(1, α_min).
    pub singular: Option<PowerLaw>,
    pub time: TimeError,
    pub combine: Combine,
}

impl ErrorModel {
    pub fn space_error(&self, h: f64) -> f64 {
        self.space.at(h).hypot(self.singular.map_or(0.0, |s| s.at(h)))
    }

    pub fn time_error(&self, k: f64) -> f64 {
        self.time.at(k)
    }

    /// The predicted error at mesh size h and time step k.
    pub fn predict(&self, h: f64, k: f64) -> f64 {
        self.combine(self.space_error(h), self.time_error(k))
    }

    /// e_h ⊕ e_k for given parts.
    pub fn combine(&self, space: f64, time: f64) -> f64 {
        match self.combine {
            Combine::Quadrature => space.hypot(time),
            Combine::Sum => space + time,
        }
    }
}

/// Exponent range of the set-up cost (module doc): at most sparse Cholesky's n^1.5 on a 2D mesh, at least
/// n^1.2, the growth the set-up shows at the plans' sizes, where the factor's O(n log n) entries outgrow the
/// caches (mms_stop, refine 3 → 6: 0.047, 0.44, 1.41, 7.7 s at 6k, 25k, 98k, 393k unknowns, n^1.23 over the
/// range). Pilot levels of a few thousand unknowns are bound by overheads and show n^0.8–1.0: an exponent
/// from them alone predicted refine 5 at half its set-up.
pub const SETUP_EXPONENT: (f64, f64) = (1.2, 1.5);

/// Seconds from which a pilot level's set-up is timed well enough for the set-up exponent to be fitted
/// through it (module doc): a tenth of a second is many scheduler slices, against the milliseconds of the
/// small levels whose times scatter 1.5× between passes.
pub const MEASURABLE_SETUP: f64 = 0.1;

/// One measured run: unknowns, set-up seconds, seconds per step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostSample {
    pub n: f64,
    pub setup: f64,
    pub step: f64,
}

/// wall(n, N) = S(n) + N s(n) (module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostModel {
    pub setup: PowerLaw,
    /// s(n) = c n ln n.
    pub step: f64,
}

impl CostModel {
    /// Fit S to the `space` samples: exponent from the two largest n where both set-ups are measurable
    /// ([`MEASURABLE_SETUP`]; else the least, [`SETUP_EXPONENT`]`.0`), clamped to [`SETUP_EXPONENT`], the
    /// constant the smallest the two imply; and s(n) = c n ln n with c the smallest the `time` samples with
    /// at least half the most steps per set-up imply (module doc: why minima). None without samples.
    pub fn fit(space: &[CostSample], time: &[(CostSample, usize)]) -> Option<CostModel> {
        // a phase too fast for the clock still costs something
        fn floor(t: f64) -> f64 {
            t.max(1e-9)
        }
        let mut s: Vec<CostSample> = space.iter().copied().filter(|c| c.n > 1.0).collect();
        s.sort_by(|a, b| a.n.total_cmp(&b.n));
        let finest = &s[s.len().saturating_sub(2)..];
        let alpha = match finest {
            [a, b] if a.setup >= MEASURABLE_SETUP && b.setup >= MEASURABLE_SETUP => {
                let e = (b.setup / a.setup).ln() / (b.n / a.n).ln();
                if e.is_finite() {
                    e.clamp(SETUP_EXPONENT.0, SETUP_EXPONENT.1)
                } else {
                    SETUP_EXPONENT.0
                }
            }
            _ => SETUP_EXPONENT.0,
        };
        let setup_c = finest.iter().map(|c| floor(c.setup) / c.n.powf(alpha)).reduce(f64::min)?;
        let time: Vec<(CostSample, usize)> = time.iter().copied().filter(|(c, _)| c.n > 1.0).collect();
        let most = time.iter().map(|&(_, steps)| steps).max()?;
        let step = time
            .iter()
            .filter(|&&(_, steps)| 2 * steps >= most)
            .map(|(c, _)| floor(c.step) / (c.n * c.n.ln()))
            .reduce(f64::min)?;
        Some(CostModel { setup: PowerLaw { c: setup_c, p: alpha }, step })
    }

    /// Seconds per step at n unknowns.
    pub fn step_at(&self, n: f64) -> f64 {
        self.step * n * n.max(2.0).ln()
    }

    /// Predicted wall time of a run with n unknowns and `steps` steps.
    pub fn predict(&self, n: f64, steps: usize) -> f64 {
        self.setup.at(n) + steps as f64 * self.step_at(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A power law through a point returns that point, and solve inverts at.
    #[test]
    fn power_law_round_trip() {
        let l = PowerLaw::through(0.25, 0.03, 1.2);
        assert!((l.at(0.25) - 0.03).abs() < 1e-15);
        assert!((l.solve(l.at(0.07)) - 0.07).abs() < 1e-14);
    }

    /// Quadrature is the Euclidean sum, Sum the plain one; no time law means no time error.
    #[test]
    fn error_parts_combine() {
        let space = PowerLaw { c: 3.0, p: 1.0 };
        let time = TimeError::Law(PowerLaw { c: 4.0, p: 1.0 });
        let q = ErrorModel { space, singular: None, time, combine: Combine::Quadrature };
        assert!((q.predict(1.0, 1.0) - 5.0).abs() < 1e-14);
        let s = ErrorModel { combine: Combine::Sum, ..q };
        assert!((s.predict(1.0, 1.0) - 7.0).abs() < 1e-14);
        let bounded = ErrorModel { time: TimeError::Bound(0.0), ..q };
        assert_eq!(bounded.predict(0.5, 1e9), 1.5);
    }

    /// The bound holds for errors e_k = C k^{1/2} (the slowest accepted) on levels N, 2N, 4N, 8N: the
    /// coarsest level's error equals the bound computed from the successive distances (parallel errors,
    /// so the distances are differences of the errors), and exceeds it for no faster order.
    #[test]
    fn time_bound_covers_the_slowest_order() {
        for q in [0.5, 1.0, 2.0] {
            let e: Vec<f64> = (0..4).map(|j| 0.3 * (0.1 / 2f64.powi(j)).powf(q)).collect();
            let sum: f64 = e.windows(2).map(|w| w[0] - w[1]).sum();
            let b = TimeError::bound(sum, 2.0, 4).at(0.1);
            assert!(b >= e[0] * (1.0 - 1e-12), "q = {q}: bound {b} < error {}", e[0]);
            if q == 0.5 {
                assert!((b / e[0] - 1.0).abs() < 1e-12);
            }
        }
    }

    /// Samples of S = 1e-5 n^1.3 (set-ups of 0.08–3 s) and s = 1e-8 n ln n give back those laws; a set-up
    /// slope outside the allowed range is clamped (a flat, overhead-dominated set-up is taken as linear).
    #[test]
    fn cost_fit_recovers_and_clamps() {
        let sample = |n: f64| CostSample { n, setup: 1e-5 * n.powf(1.3), step: 1e-8 * n * n.ln() };
        let space: Vec<CostSample> = [1e3, 4e3, 1.6e4].iter().map(|&n| sample(n)).collect();
        let time = [(sample(1e3), 10), (sample(2e3), 400), (CostSample { step: 1.0, ..sample(5e2) }, 40)];
        let m = CostModel::fit(&space, &time).unwrap();
        assert!((m.setup.p - 1.3).abs() < 1e-12);
        let n: f64 = 1e6;
        let want = 1e-5 * n.powf(1.3) + 10.0 * 1e-8 * n * n.ln();
        assert!((m.predict(n, 10) / want - 1.0).abs() < 1e-12);
        let flat = [CostSample { n: 1e3, setup: 0.2, step: 0.0 }, CostSample { n: 4e3, setup: 0.22, step: 0.0 }];
        assert_eq!(CostModel::fit(&flat, &time).unwrap().setup.p, SETUP_EXPONENT.0);
        assert!(CostModel::fit(&[], &time).is_none() && CostModel::fit(&space, &[]).is_none());
    }

    /// A slow sample does not move the model: the finest set-up timed 1.5× slow (noise only adds) leaves the
    /// constant of the level below it, whose set-up of 22 ms is too short for an exponent (the least growth
    /// is taken), and a long time level timed slow leaves the other long level's constant.
    #[test]
    fn a_slow_sample_does_not_move_the_fit() {
        let law = |n: f64| 1e-6 * n.powf(1.2);
        let step = |n: f64| 1e-8 * n * n.ln();
        let sample = |n: f64, slow: f64| CostSample { n, setup: slow * law(n), step: slow * step(n) };
        let space = [sample(1e3, 1.0), sample(4e3, 1.0), sample(1.6e4, 1.5)];
        let time = [(sample(2e3, 1.0), 64), (sample(2e3, 1.5), 128), (sample(2e3, 0.5), 16)];
        let m = CostModel::fit(&space, &time).unwrap();
        assert_eq!(m.setup.p, SETUP_EXPONENT.0);
        let n: f64 = 2.5e5;
        assert!((m.setup.at(n) / law(n) - 1.0).abs() < 1e-12, "{m:?}");
        // the 16-step level (less than half the most steps) is not a per-step sample
        assert!((m.step_at(n) / step(n) - 1.0).abs() < 1e-12, "{m:?}");
    }
}

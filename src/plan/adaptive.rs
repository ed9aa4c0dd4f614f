//! `plan` weighs an adaptive sequence (`adapt`, Dörfler θ = [`THETA`]) against the uniform plan.
//! Its two pilots refine until a level has [`PILOT_UNKNOWNS`] of the uniform plan's unknowns (at most
//! half the pilot budget), on the space pilot's time grid (where the plan's spatial error was sampled:
//! the time pilot showed the coarser grid gives the same spatial answer), and lean: only η and the
//! unknowns are computed (no energy audit, time indicator or distance between levels). So they cost a
//! few per cent of the plan (the planner's own cost is to stay within 5 % of it).
//!
//! The adaptive route is predicted through its own error estimate (`adapt::estimate`: the indicator η
//! calibrated along the sequence against a Richardson estimate in N), not through an assumed equal
//! effectivity of η on both routes (they differ: on mms_lshape η/error is 6 → 3 uniform, 5–6 adaptive). The
//! pilot gives the law η_a = C_a N^{−r_a} in the unknowns N (least squares over its finer half) and the
//! calibration c = E/η of its last level, so the route's estimate at N is c·η_a(N). The route stops where
//! its estimate reaches [`ESTIMATE_SHARE`] of the target: the estimate's effectivity (estimate / true
//! error) is held to [0.8, 1.25] (`make verify`, `reference/adaptive.md`), so an estimate at 0.8 T means a
//! true error of at most T. Its unknowns N_a solve c·η_a(N_a) = 0.8 T. Its cost: every level of the sequence
//! is a whole run at the plan's steps — the pilot's
//! levels again and the predicted ones, N growing by the pilot's mean factor q per level up to N_a —
//! each priced by the plan's cost model at the plan's steps and scaled by κ, the pilot's measured ratio
//! of adaptive level wall to the model at the pilot's steps (the median over its finer half, at least 1:
//! estimation, marking, bisection and the distances between levels included; like the uniform route's
//! price, without the energy audit). Its memory: the pre-run estimate of the last level. The cheaper route
//! that fits the budget and memory is recommended.

use super::model::PowerLaw;
use super::{Candidate, Plan};
use crate::adapt::{adapt, Options, Row};
use crate::error::Result;
use crate::scene::budget::{available_memory, Estimate};
use crate::scene::Scene;

/// Dörfler's θ of the adaptive route.
pub const THETA: f64 = 0.5;
/// Most adaptive pilot levels (with θ = ½ the unknowns grow by about 1.3 per level).
pub const ADAPTIVE_LEVELS: usize = 20;
/// The share of the target the route's error estimate must reach (the lower end of its effectivity band).
pub const ESTIMATE_SHARE: f64 = 0.8;
/// The pilot refines until this share of the uniform plan's unknowns (three and a half uniform
/// refinements below it): deep enough for the law's rate (Example 5.1 at 1e-4: 0.481 adaptive to 3,885
/// unknowns against 0.482 to 7,267 and 0.488 to 18,106), cheap enough for the planner's 5 % of the plan.
pub const PILOT_UNKNOWNS: f64 = 1.0 / 128.0;
/// The pilot grows the unknowns at least this much: about 8 levels at θ = ½ (×1.3 per level), so that
/// its last levels are past the first four, from which the error estimate is trusted.
pub const MIN_GROWTH: f64 = 8.0;
/// Fewest levels a law is fitted to.
pub const FIT_LEVELS: usize = 4;

/// Which route the planner recommends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Route {
    Uniform,
    Adaptive,
    /// Neither fits the budget and memory.
    Neither,
}

impl Route {
    pub fn name(self) -> &'static str {
        match self {
            Route::Uniform => "uniform",
            Route::Adaptive => "adaptive",
            Route::Neither => "neither",
        }
    }
}

/// The adaptive route's prediction beside the uniform plan.
#[derive(Clone, Debug)]
pub struct AdaptivePlan {
    /// The pilot sequence (θ = ½) and its law η = c N^p (p < 0).
    pub adaptive_pilot: Vec<Row>,
    pub adaptive_law: PowerLaw,
    /// The calibration E/η of the pilot's last level (`adapt::estimate`).
    pub calibration: f64,
    /// Seconds the pilot took, and the time steps it ran (the space pilot's).
    pub pilot_wall: f64,
    pub pilot_steps: usize,
    /// The uniform route: unknowns, steps, predicted wall and memory (from the plan).
    pub uniform_unknowns: f64,
    pub uniform_wall: f64,
    pub uniform_memory: u64,
    /// The estimate the route must reach ([`ESTIMATE_SHARE`] of the target), and the indicator η predicted
    /// there.
    pub estimate_target: f64,
    pub eta: f64,
    /// The adaptive route: its time steps (the plan's), unknowns of its last level, levels in all, wall
    /// (the whole sequence), memory.
    pub steps: usize,
    pub unknowns: f64,
    pub levels: usize,
    pub wall: f64,
    pub memory: u64,
    pub choice: Route,
    pub reason: String,
}

/// Least-squares power law η = c N^p over `rows` (at least [`FIT_LEVELS`]).
fn law(rows: &[Row]) -> Option<PowerLaw> {
    let (x, y): (Vec<f64>, Vec<f64>) =
        rows.iter().filter(|r| r.estimator > 0.0).map(|r| (r.unknowns as f64, r.estimator)).unzip();
    if x.len() < FIT_LEVELS {
        return None;
    }
    let p = crate::study::orders::fitted_order(&x, &y);
    // the least-squares line passes through the means of the logarithms
    let log_mean = |v: &[f64]| (v.iter().map(|a| a.ln()).sum::<f64>() / v.len() as f64).exp();
    (p < 0.0).then(|| PowerLaw::through(log_mean(&x), log_mean(&y), p))
}

/// The pilot: up to `levels` levels of `adapt` with θ, until a level has `unknowns` unknowns or the
/// pilot would take more than `budget` seconds; lean (only η, the estimate and the unknowns are read).
fn pilot(scene: &Scene, theta: f64, levels: usize, unknowns: usize, budget: f64) -> Result<Vec<Row>> {
    let opts =
        Options { budget: Some(budget), until_unknowns: Some(unknowns), lean: true, ..Options::levels(levels, theta) };
    Ok(adapt(scene, &opts, |_| {})?.rows)
}

/// The uniform route the plan offers: its best candidate, else the cheapest over the budget.
fn uniform_route(p: &Plan) -> Option<&Candidate> {
    p.best.first().or(p.over_budget.as_ref())
}

/// Weigh the adaptive route against the plan `p` of `scene` (energy-norm target); `None` with the reason
/// when it cannot be weighed (no uniform route, a pilot too short or not converging).
pub fn weigh(scene: &Scene, p: &Plan) -> Result<std::result::Result<AdaptivePlan, String>> {
    let Some(u) = uniform_route(p) else {
        return Ok(Err("the uniform plan offers no configuration to compare with".into()));
    };
    let Some(cost) = p.cost else { return Ok(Err("no cost model".into())) };
    let start = std::time::Instant::now();
    // the pilot refines until PILOT_UNKNOWNS of the uniform plan's unknowns, within half the pilot budget
    // (and at least past the levels the estimate is trusted from, adapt::estimate::TRUSTED_FROM)
    let n0 = Estimate::of(scene, 1, false)?.unknowns as f64;
    let at_least = n0 * MIN_GROWTH;
    let until = (PILOT_UNKNOWNS * u.unknowns as f64).max(at_least).ceil() as usize;
    let share = p.options.pilot_budget / 2.0;
    // on the space pilot's time grid, where the plan's spatial error was sampled (`super::plan`)
    let nh = p.space.levels.first().map_or(scene.times.len() - 1, |l| l.steps);
    let mut s = super::pilot::pilot_scene(scene, &super::pilot::Quantity::Energy)?;
    s.set_steps(nh)?;
    let adaptive_pilot = pilot(&s, THETA, ADAPTIVE_LEVELS, until, share)?;
    let pilot_wall = start.elapsed().as_secs_f64();
    let half = |rows: &[Row]| rows.len().saturating_sub((rows.len() / 2).max(FIT_LEVELS)).min(rows.len());
    let (Some(a), Some(calibration)) = (
        law(&adaptive_pilot[half(&adaptive_pilot)..]),
        adaptive_pilot.last().and_then(|r| r.estimate.map(|e| e / r.estimator)).filter(|c| c.is_finite() && *c > 0.0),
    ) else {
        return Ok(Err(format!(
            "the pilot ({} adaptive levels) is too short, its indicator does not decrease or it has no error estimate",
            adaptive_pilot.len()
        )));
    };
    // the route stops where its estimate reaches ESTIMATE_SHARE of the target: c η_a(N_a) = 0.8 T
    let estimate_target = ESTIMATE_SHARE * p.options.target;
    let eta = estimate_target / calibration;
    let unknowns = a.solve(eta).max(1.0);
    let last = adaptive_pilot.last().expect("levels");
    let first = &adaptive_pilot[half(&adaptive_pilot)];
    let span = (last.level - first.level).max(1) as f64;
    let q = (last.unknowns as f64 / first.unknowns as f64).powf(1.0 / span).max(1.05);
    // the measured walls of the pilot's finer half against the cost model at the pilot's steps (median)
    let mut ratios: Vec<f64> =
        adaptive_pilot[half(&adaptive_pilot)..].iter().map(|r| r.wall / cost.predict(r.unknowns as f64, nh)).collect();
    ratios.sort_by(f64::total_cmp);
    let kappa = ratios[ratios.len() / 2].max(1.0);
    // the route runs the pilot's levels again at the plan's steps, then the predicted ones
    let mut wall: f64 = adaptive_pilot.iter().map(|r| kappa * cost.predict(r.unknowns as f64, u.steps)).sum();
    let (mut n, mut levels) = (last.unknowns as f64, adaptive_pilot.len());
    while n < unknowns {
        n = (n * q).min(unknowns);
        wall += kappa * cost.predict(n, u.steps);
        levels += 1;
    }
    let growth = (unknowns / last.unknowns as f64).max(1.0);
    let contact = (last.contact_edges as f64 * growth.sqrt()).ceil() as u64;
    let sizes = ((unknowns / 3.0) as u64, (unknowns / 2.0) as u64, contact);
    let memory = Estimate::of_sizes(sizes, u.steps, false).memory;
    let limit = p.options.max_memory.or_else(available_memory);
    let fits = |wall: f64, memory: u64| wall <= p.options.budget && limit.is_none_or(|m| memory <= m);
    let (fa, fu) = (fits(wall, memory), fits(u.wall, u.memory));
    let (choice, reason) = choose(fa, fu, wall, u.wall);
    Ok(Ok(AdaptivePlan {
        adaptive_pilot,
        adaptive_law: a,
        calibration,
        pilot_wall,
        pilot_steps: nh,
        uniform_unknowns: u.unknowns as f64,
        uniform_wall: u.wall,
        uniform_memory: u.memory,
        estimate_target,
        eta,
        steps: u.steps,
        unknowns,
        levels,
        wall,
        memory,
        choice,
        reason,
    }))
}

/// The route recommended, and why: the cheaper of those that fit (`fa`, `fu`: the adaptive and the
/// uniform route fit the budget and memory; `wall`, `uniform`: their predicted wall times).
fn choose(fa: bool, fu: bool, wall: f64, uniform: f64) -> (Route, String) {
    let choice = match (fa, fu) {
        (true, true) if wall < uniform => Route::Adaptive,
        (true, false) => Route::Adaptive,
        (_, true) => Route::Uniform,
        (false, false) => Route::Neither,
    };
    let reason = match choice {
        Route::Adaptive if fu => {
            format!("the adaptive route is predicted cheaper: {wall:.3e} s against {uniform:.3e} s")
        }
        Route::Adaptive => "only the adaptive route fits the budget and memory".to_string(),
        Route::Uniform if fa => format!("the uniform route is predicted cheaper: {uniform:.3e} s against {wall:.3e} s"),
        Route::Uniform => "only the uniform route fits the budget and memory".to_string(),
        Route::Neither => "neither route fits the budget and memory".to_string(),
    };
    (choice, reason)
}

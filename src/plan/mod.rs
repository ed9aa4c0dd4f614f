//! `tresca-cr plan`: from a target accuracy to the cheapest (refinement, steps, solver, tolerance).
//!
//! 1. Pilot runs ([`pilot`]): a time sequence on a coarse mesh from N/16 of the scene's N steps
//!    ([`time_base`]), and a space sequence r₀, r₀+1, …, their cost bounded by the pilot budget. The
//!    scene's N is the fewest steps a plan offers: its nodes are the times the user asked for.
//! 2. Models ([`model`]): e(h, k) = C_h hᵖ ⊕ C_k k^q from the sequences' estimates, only when their finest
//!    levels are in the asymptotic range (else a refusal naming the reason); wall(n, N) = S(n) + N s(n)
//!    from their wall times.
//! 3. Search: for each refinement r ≥ r₀ with C_h h_rᵖ below the target, the fewest steps of the time
//!    pilot's family (N₀·ratio^j, the grids on which the time model was observed) whose predicted error
//!    meets the target; the cheapest within the budget and memory is the plan, the next two (other
//!    refinements) the runners-up.
//!
//! The space pilot grows one level at a time while the plan lies more than [`MAX_EXTRAPOLATION`] levels
//! beyond it and the next level costs at most [`EXTENSION_SHARE`] of the planned run: the fewer levels a
//! prediction is extrapolated, the less an order error δ costs (a factor 2^{δm} after m levels).
//! It also grows while it is not in the asymptotic range, or while the order bound stands in for its
//! order only because its estimates are not yet consistent ([`pilot::Fit::unsettled`]).
//!
//! Solver: semismooth Newton (its iterations per step do not grow with refinement: 1–3 here, printed;
//! Uzawa's grow like 1/h, `reference/work_precision.md`). Tolerance: the natural residual is relative to
//! the force scale, so a relative error tol in μ moves u by at most about tol·‖u‖: tol = 10^⌊log₁₀(0.01
//! target/‖u‖)⌋ keeps the solver's share of the error under 1 % of the target, within [1e-12, 1e-6] (a
//! tighter one buys nothing, a looser one saves no Newton iteration worth having).

pub mod adaptive;
pub mod corners;
pub mod model;
pub mod pilot;
mod search;
pub mod step_cost;
pub mod two_term;

use crate::error::{Error, Result};
use crate::scene::budget::Estimate;
use crate::scene::{Method, Scene};
use crate::study::SetupCache;
use crate::study::{Level, LevelResult, Study};
use model::{CostModel, CostSample, ErrorModel, TimeError};
use pilot::{fit, pilot_scene, time_pilot, Fit, Quantity, Runner, TimeGrids, TimePilot};
use search::{decide, Pilots};

/// Levels of the space pilot before any extension (four: the asymptotic check needs a fourth level).
pub const SPACE_LEVELS: u32 = 4;
/// A plan may lie this many levels beyond the space pilot's finest level without extending the pilot.
pub const MAX_EXTRAPOLATION: u32 = 2;
/// The pilot is extended by a level only if that level costs at most this share of the planned run.
pub const EXTENSION_SHARE: f64 = 0.1;
/// The time step is said not to matter when the time pilot bounds its error by this share of the target.
pub const NEGLIGIBLE_SHARE: f64 = 0.01;
/// A time pilot without a regular order is not retried on coarser-spaced grids (×4) when its distances
/// already bound the time error by this share of the target: that bound then enters the prediction.
pub const TIME_BOUND_SHARE: f64 = 0.25;
/// The space pilot samples time on the time pilot's first grid only if the time grids move the solution
/// by at most this share of the spatial error on the time pilot's mesh (else it runs the scene's steps).
pub const SAMPLING_SHARE: f64 = 0.1;
/// With a time law, the space pilot runs where the time error is at most this share of the spatial error
/// (measured on mms_stop: the spatial estimate on 4, 16, 64 steps is 8.5 %, 2.6 % and < 0.5 % below its
/// limit, at time/space error ratios 2.1, 0.53 and 0.13).
pub const LAW_SAMPLING_SHARE: f64 = 0.5;
/// Deepest refinement searched (the scene's own limit).
pub(crate) const MAX_REFINE: u32 = crate::scene::MAX_REFINE;
/// Most steps searched.
pub(crate) const MAX_STEPS: usize = 1 << 22;

/// What the user asks for.
#[derive(Clone, Debug)]
pub struct Options {
    pub target: f64,
    pub quantity: Quantity,
    /// Seconds the planned run may take.
    pub budget: f64,
    /// Seconds the pilot runs may take.
    pub pilot_budget: f64,
    /// Bytes the planned run may use (default: the available memory).
    pub max_memory: Option<u64>,
}

/// One configuration and its predictions.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub refine: u32,
    pub steps: usize,
    pub unknowns: u64,
    pub h: f64,
    pub k: f64,
    pub error: f64,
    pub space_error: f64,
    pub time_error: f64,
    pub wall: f64,
    pub memory: u64,
}

/// A plan, or a refusal with the evidence gathered so far.
#[derive(Clone, Debug)]
pub struct Plan {
    pub options: Options,
    pub space: Study,
    pub space_fit: Fit,
    pub time: Study,
    pub time_fit: Fit,
    /// min(1, α_min): the energy-norm order in h the scene's corners allow (`fem::singular`), against
    /// which the space sequence is judged and beyond which it is never extrapolated.
    pub order_limit: f64,
    /// Steps grow by this factor in the time pilot and in the search.
    pub time_ratio: usize,
    /// The scene's steps: the fewest a plan offers.
    pub scene_steps: usize,
    pub error: Option<ErrorModel>,
    pub cost: Option<CostModel>,
    /// Seconds the pilot runs took.
    pub pilot_wall: f64,
    /// The plan and up to two runners-up, cheapest first (empty when refused).
    pub best: Vec<Candidate>,
    /// The cheapest configuration meeting the target beyond the budget, when none fits it.
    pub over_budget: Option<Candidate>,
    pub solver: Method,
    pub tol: f64,
    pub notes: Vec<String>,
    pub refused: Option<String>,
}

/// Cost samples of the space pilot's levels: unknowns, set-up seconds (a run of the level alone, also
/// where the pilot shared its mesh's set-up) and seconds per step.
pub(crate) fn space_samples(levels: &[LevelResult]) -> Vec<CostSample> {
    levels
        .iter()
        .map(|r| CostSample {
            n: r.dofs as f64,
            setup: r.setup + r.reused_setup,
            step: (r.wall - r.setup).max(0.0) / r.steps as f64,
        })
        .collect()
}

/// Make the plan (module doc).
pub fn plan(scene: &Scene, options: &Options) -> Result<Plan> {
    plan_with_cache(scene, options, &SetupCache::default())
}

/// [`plan`] with the pilots' set-ups in `cache` (one assembly and factorisation per pilot mesh; the
/// caller can count them, [`SetupCache::factorised`]). `cache` must be new or hold this plan's only.
pub fn plan_with_cache(scene: &Scene, options: &Options, cache: &SetupCache) -> Result<Plan> {
    let target = options.target;
    if !(target.is_finite() && target > 0.0) {
        return Err(Error::scene(&scene.file, "--target", format!("{target}: must be a positive number")));
    }
    let s = pilot_scene(scene, &options.quantity)?;
    // the guard against a nearly singular K on the time pilot's mesh, the first made
    cache.guard_first_mesh_only();
    let (r0, n0) = (s.mesh_level(), s.times.len() - 1);
    let q = &options.quantity;
    let nt = time_base(n0);
    let time_pilot_run = time_pilot(
        &s,
        TimeGrids { refine: r0 + 2, first: nt, steps: n0 },
        q,
        TIME_BOUND_SHARE * target,
        options.pilot_budget,
        cache,
    )?;
    let TimePilot { study: time, spent, .. } = &time_pilot_run;
    let time_fit = fit(time, q, None)?;
    let mesh = time.levels[0].refine;
    let on_mesh = |p: &Plan| {
        p.space.levels.iter().position(|l| l.refine == mesh).and_then(|i| p.space_fit.errors.get(i).copied())
    };
    if nt == n0 || time_fit.not_in_range().is_none() {
        // a time law: the spatial error of the time-discrete problem depends on the grid (a slip that stops
        // inside a step is partly missed on coarse grids, and so is its spatial error). The space pilot
        // runs on the coarsest grid of the law's family whose time error is at most LAW_SAMPLING_SHARE of
        // the spatial error on the time pilot's mesh (first found with the scene's steps).
        let first = space_pilot(&s, options, &time_pilot_run, &time_fit, n0, *spent, cache)?;
        let (Some(e), Some(TimeError::Law(law))) = (on_mesh(&first), first.error.map(|m| m.time)) else {
            return Ok(first);
        };
        let t_total = s.times[n0] - s.times[0];
        let mut n = nt;
        while n < n0 || (law.at(t_total / n as f64) > LAW_SAMPLING_SHARE * e && n < MAX_STEPS) {
            n *= time_pilot_run.ratio;
        }
        if n == n0 {
            return Ok(first);
        }
        let mut p = space_pilot(&s, options, &time_pilot_run, &time_fit, n, first.pilot_wall, cache)?;
        p.notes.insert(
            0,
            format!(
                "the space pilot was rerun on {n} steps, where the time error is at most {} % of the spatial error on the \
                 time pilot's mesh: on {n0} steps the missed time evolution lowers the spatial error",
                100.0 * LAW_SAMPLING_SHARE
            ),
        );
        return Ok(p);
    }
    let coarse = space_pilot(&s, options, &time_pilot_run, &time_fit, nt, *spent, cache)?;
    // sampling time on nt steps is sound when the time grids change the solution on the time pilot's
    // mesh by at most SAMPLING_SHARE of that mesh's spatial error
    let moved = time_fit.distances.iter().copied().fold(0.0, f64::max);
    match on_mesh(&coarse).as_ref() {
        Some(&e) if moved <= SAMPLING_SHARE * e => Ok(coarse),
        _ => {
            let mut p = space_pilot(&s, options, &time_pilot_run, &time_fit, n0, coarse.pilot_wall, cache)?;
            p.notes.insert(
                0,
                format!(
                    "the time grids move the solution by {moved:.2e}, more than {} % of the spatial error on their mesh: the \
                     space pilot was rerun on the scene's {n0} steps",
                    100.0 * SAMPLING_SHARE
                ),
            );
            Ok(p)
        }
    }
}

/// The space pilot on `nh` steps, extended level by level (module doc), and the plan it gives.
fn space_pilot(
    s: &Scene,
    options: &Options,
    TimePilot { study: time, ratio: time_ratio, step_costs, .. }: &TimePilot,
    time_fit: &Fit,
    nh: usize,
    mut spent: f64,
    cache: &SetupCache,
) -> Result<Plan> {
    let r0 = s.mesh_level();
    let mut run = Runner::new(s, nh, cache)?;
    let mut notes = Vec::new();
    let mut r = r0;
    loop {
        let cost = CostModel::fit(&space_samples(run.levels()), step_costs);
        let predicted = |r: u32| cost.map_or(0.0, |c| c.predict(unknowns(s, r).unwrap_or(0) as f64, nh));
        if run.levels().len() as u32 >= SPACE_LEVELS {
            let (order_limit, corner_notes) = observed_limit(s, time, run.levels())?;
            let study = run.study();
            let pilots = Pilots {
                space: &study,
                time,
                step_costs,
                time_fit,
                time_ratio: *time_ratio,
                order_limit,
                wall: spent + run.spent,
            };
            let (draft, floor) = refuse_floor(s, time, run.levels(), decide(s, options, &pilots, vec![])?)?;
            let extend = match draft.best.first() {
                // an error floor: no pilot level changes that
                _ if floor => false,
                // not yet in the asymptotic range, or bounded only for want of consistent estimates
                _ if draft.space_fit.not_in_range().is_some() || draft.space_fit.unsettled => true,
                Some(b) => b.refine > r - 1 + MAX_EXTRAPOLATION && predicted(r) <= EXTENSION_SHARE * b.wall,
                // refused for the budget: a pilot level closer to the configuration may bring it within
                None => draft.over_budget.as_ref().is_some_and(|b| {
                    b.refine > r - 1 + MAX_EXTRAPOLATION && predicted(r) <= EXTENSION_SHARE * options.budget
                }),
            };
            if !extend || r > r0 + MAX_REFINE {
                let mut done = draft;
                done.notes.splice(0..0, notes.into_iter().chain(corner_notes));
                return Ok(done);
            }
        }
        if let Some(why) = run.push(Level { refine: r, steps: nh }, predicted(r), options.pilot_budget - spent)? {
            notes.push(why);
            spent += run.spent;
            let (order_limit, corner_notes) = observed_limit(s, time, run.levels())?;
            notes.extend(corner_notes);
            let study = run.study();
            let pilots =
                Pilots { space: &study, time, step_costs, time_fit, time_ratio: *time_ratio, order_limit, wall: spent };
            let (mut done, _) = refuse_floor(s, time, run.levels(), decide(s, options, &pilots, notes)?)?;
            if done.refused.is_none() && (run.levels().len() as u32) < SPACE_LEVELS {
                done.refused = Some("fewer than four space levels: no asymptotic-range check".into());
                done.best.clear();
            }
            return Ok(done);
        }
        r += 1;
    }
}

/// The order bound with the contact corners' conditions from the states the time pilot's and the space
/// pilot's levels went through ([`corners`]), and the lines that say which were used.
fn observed_limit(s: &Scene, time: &Study, space: &[LevelResult]) -> Result<(f64, Vec<String>)> {
    let levels: Vec<&LevelResult> = time.levels.iter().chain(space).collect();
    corners::order_limit(s, &levels)
}

/// `plan` refused, with no error model, when the pilots' states give an error floor
/// ([`corners::floor_refusal`]), and whether it was.
fn refuse_floor(s: &Scene, time: &Study, space: &[LevelResult], mut plan: Plan) -> Result<(Plan, bool)> {
    let levels: Vec<&LevelResult> = time.levels.iter().chain(space).collect();
    let Some(why) = corners::floor_refusal(s, &levels)? else { return Ok((plan, false)) };
    plan.refused = Some(why);
    (plan.best, plan.over_budget, plan.error) = (vec![], None, None);
    Ok((plan, true))
}

/// The time pilot's first grid: N/2^j for the largest j ≤ 4 that divides N and leaves at least
/// min(N, 4) steps. The time pilot then shows whether grids coarser than the scene's already give its
/// answer; if so, the space pilot samples time on that grid (1/16 of the nodes at most, at least the
/// quarter points), and its levels cost a fraction of the planned run even one or two refinements below
/// it. If the time error follows a law instead, the space pilot runs the scene's N steps: the spatial
/// error of the time-discrete problem then depends on the time grid (a slip that stops inside a step).
fn time_base(n: usize) -> usize {
    (0..=4)
        .rev()
        .map(|j| 1usize << j)
        .filter(|d| n.is_multiple_of(*d))
        .map(|d| n / d)
        .find(|&m| m >= n.min(4))
        .unwrap_or(n)
}

/// Unknowns at refinement r (the budget's count, exact for structured meshes).
fn unknowns(s: &Scene, r: u32) -> Result<u64> {
    let mut t = s.clone();
    t.set_refine(r)?;
    Ok(Estimate::of(&t, 1, false)?.unknowns)
}

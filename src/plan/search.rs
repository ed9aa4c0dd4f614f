//! Step 3 of the planner (see the parent module): fit the error and cost models to the pilots and search
//! the configurations, cheapest first, for the plan, its runners-up or the refusal.

use super::model::{Combine, CostModel, CostSample, ErrorModel, PowerLaw, TimeError, ORTHOGONAL_BETA};
use super::pilot::{fit, Fit, Quantity};
use super::{
    space_samples, Candidate, Options, Plan, EXTENSION_SHARE, MAX_EXTRAPOLATION, MAX_REFINE, MAX_STEPS,
    NEGLIGIBLE_SHARE,
};
use crate::error::Result;
use crate::scene::budget::{available_memory, Estimate};
use crate::scene::{Method, Scene};
use crate::study::richardson::FS_THREE;
use crate::study::Study;

/// What the pilot runs gave: the space and time sequences, the time sequence's fit and grid ratio, and
/// the wall time they took.
pub(super) struct Pilots<'a> {
    pub(super) space: &'a Study,
    pub(super) time: &'a Study,
    /// The run's per-step cost samples on the time pilot's mesh ([`super::step_cost`]).
    pub(super) step_costs: &'a [(CostSample, usize)],
    pub(super) time_fit: &'a Fit,
    pub(super) time_ratio: usize,
    /// min(1, α_min) of the scene ([`super::Plan::order_limit`]).
    pub(super) order_limit: f64,
    pub(super) wall: f64,
}

/// Fit the models to the pilots and search (module doc).
pub(super) fn decide(s: &Scene, options: &Options, pilots: &Pilots, mut notes: Vec<String>) -> Result<Plan> {
    let Pilots { space, time, step_costs, time_fit, time_ratio, order_limit, wall } = *pilots;
    let space_fit = fit(space, &options.quantity, Some(order_limit))?;
    notes.extend(space_fit.bounded.clone());
    let cost = CostModel::fit(&space_samples(&space.levels), step_costs);
    let mut plan = Plan {
        options: options.clone(),
        space: space.clone(),
        space_fit: space_fit.clone(),
        time: time.clone(),
        time_fit: time_fit.clone(),
        order_limit,
        time_ratio,
        scene_steps: s.times.len() - 1,
        error: None,
        cost,
        pilot_wall: wall,
        best: vec![],
        over_budget: None,
        solver: Method::Ssn,
        tol: 1e-12,
        notes: vec![],
        refused: None,
    };
    if let Some(why) = space_fit.not_in_range() {
        plan.refused = Some(format!("the space pilot is not in the asymptotic range: {why}"));
        plan.notes = notes;
        return Ok(plan);
    }
    let time_law = match time_error(s, options.target, pilots, &mut notes) {
        Ok(law) => law,
        Err(why) => {
            plan.refused = Some(why);
            plan.notes = notes;
            return Ok(plan);
        }
    };
    let (hx, he) = (*space_fit.x.last().expect("levels"), *space_fit.errors.last().expect("levels"));
    let combine = match space_fit.beta {
        Some(b) if b >= ORTHOGONAL_BETA => Combine::Quadrature,
        _ => Combine::Sum,
    };
    let (smooth, singular) = match space_fit.two_term {
        Some([g, e, p]) => (PowerLaw::through(hx, g, p), Some(PowerLaw::through(hx, e, space_fit.p))),
        None => (PowerLaw::through(hx, he, space_fit.p), None),
    };
    let error = ErrorModel { space: smooth, singular, time: time_law, combine };
    plan.error = Some(error);
    let Some(cost) = cost else {
        plan.refused = Some("no pilot run to fit the cost model to".into());
        return Ok(plan);
    };
    // at a pilot's own refinement its estimate where it is above the model, its GCI where below (`at_pilot`)
    let floor: Vec<(u32, f64)> = space.levels.iter().map(|l| l.refine).zip(space_fit.errors.iter().copied()).collect();
    let all = candidates(s, options.target, pilots, (&error, &floor), &cost)?;
    choose(&mut plan, all, notes);
    Ok(plan)
}

/// The time part of the error model: the time pilot's law when it is in the asymptotic range, else the
/// bound from its distances (noted), or why neither serves (the bound is above `target`).
fn time_error(
    s: &Scene,
    target: f64,
    pilots: &Pilots,
    notes: &mut Vec<String>,
) -> std::result::Result<TimeError, String> {
    let Pilots { time, time_fit, time_ratio, .. } = *pilots;
    let n0 = s.times.len() - 1;
    let nt = time.levels[0].steps;
    if let (None, Some(&x), Some(&e)) = (time_fit.not_in_range(), time_fit.x.last(), time_fit.errors.last()) {
        if time_ratio == 4 {
            notes.push(format!(
                "on time grids doubling from {nt} steps the observed orders were irregular (a slip that stops inside a \
                 step: the error depends on where in the step it stops); on grids ×4 they are regular, so only \
                 N = {nt}·4^j is offered"
            ));
        }
        return Ok(TimeError::Law(PowerLaw::through(x, e, time_fit.p)));
    }
    let steps: Vec<usize> = time.levels.iter().map(|l| l.steps).collect();
    let bound = time_fit.time_bound(&steps, n0, time_ratio);
    let b = bound.at(0.0);
    if b > target {
        return Err(format!(
            "the time pilot (steps {}) is not in the asymptotic range ({}) and its distances only bound the time \
             error by {b:.3e}, above the target",
            steps_list(time),
            time_fit.not_in_range().unwrap_or_default()
        ));
    }
    notes.push(if b <= NEGLIGIBLE_SHARE * target {
        format!(
            "the time step does not change the answer: the time levels {} bound the time error by {b:.2e} (≤ {} % \
             of the target); backward Euler is exact at the nodes for these data (a proportional load, or points \
             that only pass from stick to slip), so the scene's {n0} steps suffice and more steps only add output times",
            steps_list(time),
            100.0 * NEGLIGIBLE_SHARE
        )
    } else {
        format!(
            "the time pilot (steps {}) shows no regular order ({}); its distances bound the time error by {b:.2e} \
             for any N ≥ {n0} (see plan::model::TimeError), which the plan uses",
            steps_list(time),
            time_fit.not_in_range().unwrap_or_default()
        )
    });
    Ok(bound)
}

/// Per mesh from the scene's up to [`MAX_REFINE`], the fewest steps on the time law's grids predicted to
/// meet `target`, with its predicted cost and memory; the space error at a pilot's refinement is at least
/// that pilot level's estimate, at most its GCI (`floor`: refinement, estimate; [`at_pilot`]).
fn candidates(
    s: &Scene,
    target: f64,
    pilots: &Pilots,
    (model, floor): (&ErrorModel, &[(u32, f64)]),
    cost: &CostModel,
) -> Result<Vec<Candidate>> {
    let (finest, time) = (pilots.space.levels.last().expect("levels"), pilots.time);
    let n0 = s.times.len() - 1;
    let t_total = s.times[n0] - s.times[0];
    let ratio = if matches!(model.time, TimeError::Law(_)) { pilots.time_ratio } else { 1 };
    let mut all = Vec::new();
    for r in s.mesh_level()..=MAX_REFINE {
        let h = finest.h * 0.5f64.powi(r as i32 - finest.refine as i32);
        let error = &match floor.iter().find(|&&(q, _)| q == r).and_then(|&(_, e)| at_pilot(e, model.space_error(h))) {
            Some(e) => ErrorModel { space: PowerLaw::through(h, e, model.space.p), singular: None, ..*model },
            None => *model,
        };
        if error.space_error(h) >= target {
            continue;
        }
        // the time law's grids (the pilot's first grid times ratio^j) from the scene's N on
        let mut n = if ratio == 1 { n0 } else { time.levels[0].steps };
        while n < n0 {
            n *= ratio;
        }
        while n <= MAX_STEPS {
            let k = t_total / n as f64;
            let e = error.predict(h, k);
            if e <= target {
                let mut t = s.clone();
                t.set_refine(r)?;
                let est = Estimate::of(&t, n, false)?;
                all.push(Candidate {
                    refine: r,
                    steps: n,
                    unknowns: est.unknowns,
                    h,
                    k,
                    error: e,
                    space_error: error.space_error(h),
                    time_error: error.time_error(k),
                    wall: cost.predict(est.unknowns as f64, n),
                    memory: est.memory,
                });
                break;
            }
            if ratio == 1 {
                break;
            }
            n *= ratio;
        }
    }
    Ok(all)
}

/// The spatial error at a pilot's own refinement, where it differs from the model's `model`: the level's
/// estimate `estimate` where it is above the model (an order bound below the observed one extrapolates
/// backwards below the coarser levels' errors), its GCI (Roache's band F_s·estimate, F_s = 1.25 with three
/// or more levels) where that is below the model (an order still rising towards the bound: the finest level's
/// law extrapolated backwards lies above the coarser levels' errors, near_incompressible's refine 0 at 6.0
/// against the true 4.03, its estimate 3.69).
fn at_pilot(estimate: f64, model: f64) -> Option<f64> {
    let gci = FS_THREE * estimate;
    (estimate > model).then_some(estimate).or((gci < model).then_some(gci))
}

/// The plan and two runners-up among `all` within the budget and memory, cheapest first, with the
/// solver tolerance for the plan; or the refusal naming the cheapest configuration beyond them.
fn choose(plan: &mut Plan, all: Vec<Candidate>, mut notes: Vec<String>) {
    let options = &plan.options;
    let finest = plan.space.levels.last().expect("levels");
    let memory_limit = options.max_memory.or_else(available_memory);
    let fits = |c: &Candidate| memory_limit.is_none_or(|m| c.memory <= m);
    let mut ok: Vec<Candidate> = all.iter().filter(|c| fits(c) && c.wall <= options.budget).cloned().collect();
    ok.sort_by(|a, b| a.wall.total_cmp(&b.wall));
    ok.truncate(3);
    if ok.is_empty() {
        let cheapest = |f: &dyn Fn(&Candidate) -> bool| {
            all.iter().filter(|c| f(c)).min_by(|a, b| a.wall.total_cmp(&b.wall)).cloned()
        };
        let over_budget = cheapest(&|c| fits(c)).or_else(|| cheapest(&|_| true));
        plan.refused = Some(match &over_budget {
            Some(c) => format!(
                "the target is out of reach within the budget of {:.0} s and {} of memory: the cheapest configuration \
                 predicted to meet it (refine {}, {} steps, {} unknowns) would take {:.3e} s and {}",
                options.budget,
                memory_limit.map_or("any amount".into(), crate::error::human),
                c.refine,
                c.steps,
                c.unknowns,
                c.wall,
                crate::error::human(c.memory)
            ),
            None => format!(
                "the target is out of reach: no configuration up to refine {MAX_REFINE} and {MAX_STEPS} steps is predicted to meet it"
            ),
        });
        plan.over_budget = over_budget;
    } else {
        let b = &ok[0];
        if b.refine > finest.refine + MAX_EXTRAPOLATION {
            notes.push(format!(
                "the plan is {} levels beyond the pilot's finest (refine {}): extending the pilot would cost more than {} % of the run",
                b.refine - finest.refine,
                finest.refine,
                100.0 * EXTENSION_SHARE
            ));
        }
        let scale = match &options.quantity {
            Quantity::Energy => finest.norm_max,
            Quantity::Output(name) => {
                let i = plan.space.output_names.iter().position(|n| n == name).unwrap_or(0);
                finest.outputs.get(i).map_or(0.0, |v| v.abs())
            }
        };
        let target = options.target;
        plan.tol =
            if scale > 0.0 { 10f64.powf((0.01 * target / scale).log10().floor()).clamp(1e-12, 1e-6) } else { 1e-12 };
    }
    plan.best = ok;
    plan.notes = notes;
}

fn steps_list(study: &Study) -> String {
    study.levels.iter().map(|l| l.steps.to_string()).collect::<Vec<_>>().join(", ")
}

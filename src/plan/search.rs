//! Step 3 of the planner (see the parent module): fit the error and cost models to the pilots and search
//! the configurations, cheapest first, for the plan, its runners-up or the refusal.

use super::model::{Combine, CostModel, ErrorModel, PowerLaw, TimeError, ORTHOGONAL_BETA};
use super::pilot::{fit, Fit, Quantity};
use super::{
    samples, space_samples, Candidate, Options, Plan, EXTENSION_SHARE, MAX_EXTRAPOLATION, MAX_REFINE, MAX_STEPS,
    NEGLIGIBLE_SHARE,
};
use crate::error::Result;
use crate::scene::budget::{available_memory, Estimate};
use crate::scene::{Method, Scene};
use crate::study::Study;

/// Fit the models to the pilots and search (module doc).
#[allow(clippy::too_many_arguments)]
pub(super) fn decide(
    s: &Scene,
    options: &Options,
    space: &Study,
    time: &Study,
    time_fit: &Fit,
    time_ratio: usize,
    pilot_wall: f64,
    mut notes: Vec<String>,
) -> Result<Plan> {
    let target = options.target;
    let space_fit = fit(space, &options.quantity)?;
    let cost = CostModel::fit(&space_samples(&space.levels), &samples(&time.levels));
    let mut plan = Plan {
        options: options.clone(),
        space: space.clone(),
        space_fit: space_fit.clone(),
        time: time.clone(),
        time_fit: time_fit.clone(),
        time_ratio,
        scene_steps: s.times.len() - 1,
        error: None,
        cost,
        pilot_wall,
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
    let n0 = s.times.len() - 1;
    let nt = time.levels[0].steps;
    let t_total = s.times[n0] - s.times[0];
    let law = match (time_fit.not_in_range(), time_fit.x.last(), time_fit.errors.last()) {
        (None, Some(&x), Some(&e)) => Some(TimeError::Law(PowerLaw::through(x, e, time_fit.p))),
        _ => None,
    };
    let time_law = match law {
        Some(law) => {
            if time_ratio == 4 {
                notes.push(format!(
                    "on time grids doubling from {nt} steps the observed orders were irregular (a slip that stops inside a \
                     step: the error depends on where in the step it stops); on grids ×4 they are regular, so only \
                     N = {nt}·4^j is offered"
                ));
            }
            law
        }
        None => {
            let steps: Vec<usize> = time.levels.iter().map(|l| l.steps).collect();
            let bound = time_fit.time_bound(&steps, n0, time_ratio);
            let b = bound.at(0.0);
            if b > target {
                plan.refused = Some(format!(
                    "the time pilot (steps {}) is not in the asymptotic range ({}) and its distances only bound the time \
                     error by {b:.3e}, above the target",
                    steps_list(time),
                    time_fit.not_in_range().unwrap_or_default()
                ));
                plan.notes = notes;
                return Ok(plan);
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
            bound
        }
    };
    let (hx, he) = (*space_fit.x.last().expect("levels"), *space_fit.errors.last().expect("levels"));
    let combine = match space_fit.beta {
        Some(b) if b >= ORTHOGONAL_BETA => Combine::Quadrature,
        _ => Combine::Sum,
    };
    let error = ErrorModel { space: PowerLaw::through(hx, he, space_fit.p), time: time_law, combine };
    plan.error = Some(error);
    let Some(cost) = cost else {
        plan.refused = Some("no pilot run to fit the cost model to".into());
        return Ok(plan);
    };
    let finest = space.levels.last().expect("levels");
    let memory_limit = options.max_memory.or_else(available_memory);
    let ratio = if matches!(error.time, TimeError::Law(_)) { time_ratio } else { 1 };
    let mut all = Vec::new();
    for r in s.mesh_level()..=MAX_REFINE {
        let h = finest.h * 0.5f64.powi(r as i32 - finest.refine as i32);
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
    let fits = |c: &Candidate| memory_limit.is_none_or(|m| c.memory <= m);
    let mut ok: Vec<Candidate> = all.iter().filter(|c| fits(c) && c.wall <= options.budget).cloned().collect();
    ok.sort_by(|a, b| a.wall.total_cmp(&b.wall));
    ok.truncate(3);
    if ok.is_empty() {
        let cheapest = |f: &dyn Fn(&Candidate) -> bool| {
            all.iter().filter(|c| f(c)).min_by(|a, b| a.wall.total_cmp(&b.wall)).cloned()
        };
        plan.over_budget = cheapest(&|c| fits(c)).or_else(|| cheapest(&|_| true));
        plan.refused = Some(match &plan.over_budget {
            Some(c) => format!(
                "the target is out of reach within the budget of {:.0} s and {} of memory: the cheapest configuration \
                 predicted to meet it (refine {}, {} steps, {} unknowns) would take {:.3e} s and {:.1} GB",
                options.budget,
                memory_limit.map_or("any amount".into(), |m| format!("{:.1} GB", m as f64 / 1e9)),
                c.refine,
                c.steps,
                c.unknowns,
                c.wall,
                c.memory as f64 / 1e9
            ),
            None => format!(
                "the target is out of reach: no configuration up to refine {MAX_REFINE} and {MAX_STEPS} steps is predicted to meet it"
            ),
        });
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
                let i = space.output_names.iter().position(|n| n == name).unwrap_or(0);
                finest.outputs.get(i).map_or(0.0, |v| v.abs())
            }
        };
        plan.tol =
            if scale > 0.0 { 10f64.powf((0.01 * target / scale).log10().floor()).clamp(1e-12, 1e-6) } else { 1e-12 };
    }
    plan.best = ok;
    plan.notes = notes;
    Ok(plan)
}

fn steps_list(study: &Study) -> String {
    study.levels.iter().map(|l| l.steps.to_string()).collect::<Vec<_>>().join(", ")
}

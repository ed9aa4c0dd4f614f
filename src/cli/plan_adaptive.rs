//! `tresca-cr plan`'s adaptive route: weigh it against the uniform plan (`plan::adaptive`) and print both.

use super::out::say;
use anyhow::Result;
use tresca_cr::adapt::Row;
use tresca_cr::plan::adaptive::{weigh as weigh_routes, AdaptivePlan, Route};
use tresca_cr::plan::pilot::Quantity;
// a uniform space fit at or above CR's optimal order less the pilots' scatter leaves the adaptive route
// nothing to gain but its overhead
use tresca_cr::plan::two_term::{OPTIMAL_ORDER, ORDER_SCATTER};
use tresca_cr::plan::Plan;
use tresca_cr::Scene;

/// Weigh and print; `None` for targets the indicator does not bound (outputs other than the energy norm),
/// when the uniform plan has no error model, or when its observed space order is already optimal (then the
/// adaptive pilots would only add to the planner's cost, which is to stay within 5 % of the plan).
pub fn weigh(scene: &Scene, p: &Plan) -> Result<Option<std::result::Result<AdaptivePlan, String>>> {
    let Some(model) = p.error.as_ref().filter(|_| p.options.quantity == Quantity::Energy) else {
        return Ok(None);
    };
    // the order the pilot observed, not the model's (which the scene's corners may bound below it)
    let observed = p.space.estimates.model.map_or(model.space.p, |m| m.p);
    if observed >= OPTIMAL_ORDER - ORDER_SCATTER {
        say!(
            "\nAdaptive route not weighed: the uniform space order {observed:.3} is optimal for CR (≥ {}), so adaptive \
             refinement cannot reach the target with fewer unknowns by more than its overhead",
            OPTIMAL_ORDER - ORDER_SCATTER
        );
        return Ok(None);
    }
    say!("\nAdaptive route (θ = {}), weighed through its error estimate:", tresca_cr::plan::adaptive::THETA);
    let w = weigh_routes(scene, p)?;
    match &w {
        Err(why) => say!("  not weighed: {why}"),
        Ok(a) => print(a, &scene.file),
    }
    Ok(Some(w))
}

fn print(a: &AdaptivePlan, file: &str) {
    let line = |name: &str, rows: &[Row]| {
        let n: Vec<String> = rows.iter().map(|r| format!("{}:{:.3e}", r.unknowns, r.estimator)).collect();
        say!("  {name} pilot (unknowns:η): {}", n.join(" "));
    };
    line("adaptive", &a.adaptive_pilot);
    say!(
        "  η ∝ N^(−{:.3}); estimate = {:.3} η (its last level); pilot {:.3} s on {} steps; the route stops at an estimate \
         of {:.3e} ({} of the target), predicted at η = {:.3e}",
        -a.adaptive_law.p,
        a.calibration,
        a.pilot_wall,
        a.pilot_steps,
        a.estimate_target,
        tresca_cr::plan::adaptive::ESTIMATE_SHARE,
        a.eta
    );
    say!("  {:>9} {:>12} {:>7} {:>11} {:>9}", "route", "unknowns", "levels", "pred wall", "memory");
    say!(
        "  {:>9} {:>12.0} {:>7} {:>10.3e}s {:>8}M",
        "uniform",
        a.uniform_unknowns,
        1,
        a.uniform_wall,
        a.uniform_memory >> 20
    );
    say!("  {:>9} {:>12.0} {:>7} {:>10.3e}s {:>8}M", "adaptive", a.unknowns, a.levels, a.wall, a.memory >> 20);
    say!("  recommended: {} ({})", a.choice.name(), a.reason);
    if a.choice == Route::Adaptive {
        say!(
            "  run it: tresca-cr adapt {file} --target {:.3e} --theta {} --steps {}",
            a.estimate_target,
            tresca_cr::plan::adaptive::THETA,
            a.steps
        );
    }
}

/// `plan --run` where the adaptive route is recommended: its `adapt` loop (θ, the plan's steps, until the error estimate
/// ≤ 0.8 T, under the same memory and disk checks as `tresca-cr adapt` and the plan's memory limit and
/// wall budget), printed as `adapt` prints it,
/// then whether it reached that η and, with an exact solution, the true error against the target. Returns the
/// exit code (3 when the loop was refused) and the loop's levels.
pub fn execute(scene: &Scene, a: &AdaptivePlan, p: &Plan) -> Result<(i32, Vec<Row>)> {
    let target = p.options.target;
    let mut s = scene.clone();
    s.set_steps(a.steps)?;
    let opts = tresca_cr::adapt::Options {
        target: Some(a.estimate_target),
        levels: None,
        max_memory: p.options.max_memory,
        budget: Some(p.options.budget),
        ..tresca_cr::adapt::Options::levels(0, tresca_cr::plan::adaptive::THETA)
    };
    say!(
        "\nRunning the adaptive route (θ = {}, {} steps, until the error estimate ≤ {:.3e}):",
        opts.theta,
        a.steps,
        a.estimate_target
    );
    let (code, rows) = super::adapt::run_rows(s, opts, None, None)?;
    if let Some(last) = rows.last() {
        let estimate = last.estimate.unwrap_or(f64::INFINITY);
        say!(
            "reached the error estimate {estimate:.4e} (η = {:.4e}) with {} unknowns against {:.3e}: {}",
            last.estimator,
            last.unknowns,
            a.estimate_target,
            if estimate <= a.estimate_target { "met" } else { "NOT met" }
        );
        if let Some(e) = last.error {
            say!(
                "true energy error (max over the time nodes) {e:.4e}: {}",
                if e <= target { "met" } else { "NOT met" }
            );
        }
    }
    Ok((code, rows))
}

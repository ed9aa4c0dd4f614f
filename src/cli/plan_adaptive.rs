//! `tresca-cr plan`'s adaptive route: weigh it against the uniform plan (`plan::adaptive`) and print both.

use super::out::say;
use anyhow::Result;
use tresca_cr::adapt::Row;
use tresca_cr::plan::adaptive::{weigh as weigh_routes, AdaptivePlan};
use tresca_cr::plan::pilot::Quantity;
use tresca_cr::plan::Plan;
use tresca_cr::Scene;

/// Weigh and print; `None` for targets the indicator does not bound (outputs other than the energy norm)
/// or when the uniform plan has no error model.
pub fn weigh(scene: &Scene, p: &Plan) -> Result<Option<std::result::Result<AdaptivePlan, String>>> {
    if p.options.quantity != Quantity::Energy || p.error.is_none() {
        return Ok(None);
    }
    say!("\nAdaptive route (θ = {}), weighed through the error indicator η:", tresca_cr::plan::adaptive::THETA);
    let w = weigh_routes(scene, p)?;
    match &w {
        Err(why) => say!("  not weighed: {why}"),
        Ok(a) => print(a),
    }
    Ok(Some(w))
}

fn print(a: &AdaptivePlan) {
    let line = |name: &str, rows: &[Row]| {
        let n: Vec<String> = rows.iter().map(|r| format!("{}:{:.3e}", r.unknowns, r.estimator)).collect();
        say!("  {name} pilot (unknowns:η): {}", n.join(" "));
    };
    line("adaptive", &a.adaptive_pilot);
    line("uniform", &a.uniform_pilot);
    say!(
        "  η ∝ N^(−{:.3}) adaptive, N^(−{:.3}) uniform; pilots {:.3} s; the uniform plan's {:.0} unknowns mean η = {:.3e}",
        -a.adaptive_law.p,
        -a.uniform_law.p,
        a.pilot_wall,
        a.uniform_unknowns,
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
}

//! `tresca-cr plan`: print the pilot's evidence, the fitted models and the cheapest configuration predicted
//! to meet the target (or the refusal), optionally write them as CSV, and with `--run` run the plan (the
//! adaptive route's `adapt` loop where that route is recommended) and
//! report the achieved error estimate (and the true error when the scene has `[exact]`).

use super::out::{note, say};
use anyhow::Result;
use std::path::PathBuf;
use tresca_cr::output::guard::Outputs;
use tresca_cr::plan::model::{Combine, TimeError};
use tresca_cr::plan::pilot::{fit, Quantity};
use tresca_cr::plan::{plan, Candidate, Options, Plan};
use tresca_cr::study::orders::successive_orders;
use tresca_cr::study::{run_study, Level, Study};
use tresca_cr::Scene;

type Weighed = std::result::Result<tresca_cr::plan::adaptive::AdaptivePlan, String>;

/// The adaptive route was weighed and recommended.
fn adaptive_chosen(w: &Option<Weighed>) -> bool {
    matches!(w, Some(Ok(a)) if a.choice == tresca_cr::plan::adaptive::Route::Adaptive)
}

/// Exit code of a refusal (no plan; errors exit with 1, command-line usage errors with 2 as clap does).
pub const REFUSED: i32 = 3;

/// Plan (and with `weigh_adaptive` weigh the adaptive route beside it); returns the exit code.
pub fn run(
    scene: Scene,
    options: Options,
    csv: Option<PathBuf>,
    execute: bool,
    weigh_adaptive: bool,
    reports: super::summary::Reports,
) -> Result<i32> {
    let start = std::time::Instant::now();
    let (json, force) = (reports.json, reports.force);
    let outputs = Outputs::new(force).inputs_of(&scene);
    outputs.files(csv.as_deref(), "--csv file").files(json.as_deref(), "--json file").check()?;
    let exact = scene.exact.is_some();
    let summarise = |p: &Plan, achieved, adaptive: &Option<Weighed>, ran: &[tresca_cr::adapt::Row]| -> Result<()> {
        let Some(j) = &json else { return Ok(()) };
        let mut s = super::summary::Summary::new("plan", &scene.file, start.elapsed().as_secs_f64());
        let mut ps = super::summary::PlanSummary::of(p, &p.options.quantity.describe(), achieved);
        ps.adaptive = adaptive.as_ref().map(|w| super::summary::AdaptiveRoute::of(w, exact));
        if let Some(a) = ps.adaptive.as_mut() {
            a.run = ran.iter().map(|r| super::summary::AdaptLevel::of(r, exact)).collect();
        }
        s.plan = Some(ps);
        if let Some(why) = &p.refused {
            if !adaptive_chosen(adaptive) {
                s.status = format!("refused: {why}");
            }
        }
        super::summary::write(j, &s, force)
    };
    say!("Planning {} for the {} ≤ {:e}", scene.file, options.quantity.describe(), options.target);
    let p = plan(&scene, &options)?;
    print_evidence(&p);
    if let Some(path) = &csv {
        tresca_cr::output::guard::write_new(path, "--csv file", csv_text(&p).as_bytes(), force)?;
    }
    for n in &p.notes {
        say!("note: {n}");
    }
    let adaptive = if weigh_adaptive { super::plan_adaptive::weigh(&scene, &p)? } else { None };
    if let Some(why) = &p.refused {
        let chosen = adaptive_chosen(&adaptive);
        say!("\n{}: {why}", if chosen { "No uniform plan (the adaptive route above is)" } else { "No plan" });
        if let (true, Some(Ok(a))) = (chosen && execute, &adaptive) {
            let (code, rows) = super::plan_adaptive::execute(&scene, a, &p)?;
            summarise(&p, None, &adaptive, &rows)?;
            super::out::report_written(csv.as_deref())?;
            return Ok(code);
        }
        summarise(&p, None, &adaptive, &[])?;
        super::out::report_written(csv.as_deref())?;
        return Ok(if chosen { 0 } else { REFUSED });
    }
    print_table(&p);
    let b = &p.best[0];
    say!(
        "\nrun it: tresca-cr run {} --refine {} --steps {} --solver {} --tol {:e}",
        scene.file,
        b.refine,
        b.steps,
        p.solver,
        p.tol
    );
    if execute {
        if let Some(Ok(a)) = adaptive.as_ref().filter(|_| adaptive_chosen(&adaptive)) {
            let (code, rows) = super::plan_adaptive::execute(&scene, a, &p)?;
            summarise(&p, None, &adaptive, &rows)?;
            super::out::report_written(csv.as_deref())?;
            return Ok(code);
        }
    }
    let achieved = if execute { Some(execute_plan(&scene, &p, b)?) } else { None };
    summarise(&p, achieved, &adaptive, &[])?;
    super::out::report_written(csv.as_deref())?;
    Ok(0)
}

/// The plan and its runners-up, one line each.
fn print_table(p: &Plan) {
    say!(
        "\n{:>8} {:>6} {:>7} {:>10} {:>6} {:>8} {:>11} {:>11} {:>11} {:>11} {:>9}",
        "",
        "refine",
        "steps",
        "unknowns",
        "solver",
        "tol",
        "pred error",
        "space",
        "time",
        "pred wall",
        "memory"
    );
    for (i, c) in p.best.iter().enumerate() {
        let role = if i == 0 { "plan" } else { "runner-up" };
        say!(
            "{role:>8} {:>6} {:>7} {:>10} {:>6} {:>8.0e} {:>11.4e} {:>11.4e} {:>11.4e} {:>10.3}s {:>8}M",
            c.refine,
            c.steps,
            c.unknowns,
            p.solver,
            p.tol,
            c.error,
            c.space_error,
            c.time_error,
            c.wall,
            c.memory >> 20
        );
    }
}

/// The pilot runs of one sequence (time or space) with their estimated errors and verdicts.
fn print_sequence(name: &str, study: &Study, fit: &tresca_cr::plan::pilot::Fit) {
    say!("  {name} sequence, sizes {}:", fit.size);
    say!(
        "  {:>6} {:>7} {:>9} {:>10} {:>9} {:>9} {:>7} {:>11}  verdict",
        "refine",
        "steps",
        "h",
        "unknowns",
        "set-up",
        "wall",
        "it/step",
        "est error"
    );
    for (i, r) in study.levels.iter().enumerate() {
        let est = fit.errors.get(i).map_or("-".into(), |e| format!("{e:.4e}"));
        let verdict = fit.verdicts.get(i).map_or(String::new(), |v| v.text());
        say!(
            "  {:>6} {:>7} {:>9.3e} {:>10} {:>9.4} {:>9.4} {:>7.2} {:>11}  {}",
            r.refine,
            r.steps,
            r.h,
            r.dofs,
            r.setup,
            r.wall,
            r.iterations as f64 / r.steps as f64,
            est,
            verdict
        );
    }
    if let Some(why) = &fit.refused {
        say!("  no estimate: {why}");
    }
}

/// The pilot runs, the fitted error model and the cost model.
fn print_evidence(p: &Plan) {
    say!("\nPilot runs (the scene without [exact]; wall = set-up + steps, seconds):");
    for (name, study, fit) in [("time", &p.time, &p.time_fit), ("space", &p.space, &p.space_fit)] {
        print_sequence(name, study, fit);
    }
    say!("Pilot cost: {:.3} s (pilot budget {:.3} s)", p.pilot_wall, p.options.pilot_budget);
    say!("Order bound: min(1, α_min) = {:.4} in h (the scene's corners, `tresca-cr check`)", p.order_limit);
    let orders = |f: &tresca_cr::plan::pilot::Fit| {
        if f.errors.len() < 2 {
            return String::new();
        }
        let o = successive_orders(&f.x, &f.errors);
        format!(", successive orders {}", o.iter().map(|v| format!("{v:.3}")).collect::<Vec<_>>().join(" "))
    };
    if let Some(m) = &p.error {
        let range = |x: &[f64]| format!("[{:.3e}, {:.3e}]", x.last().copied().unwrap_or(0.0), x[0]);
        let singular = m.singular.map_or(String::new(), |s| format!(" ⊕ {:.4e} h^{:.3}", s.c, s.p));
        say!(
            "\nError model: e_h = {:.4e} h^{:.3}{singular} (h in {}{}, β = {})",
            m.space.c,
            m.space.p,
            range(&p.space_fit.x),
            orders(&p.space_fit),
            p.space_fit.beta.map_or("-".into(), |b| format!("{b:.3}"))
        );
        match m.time {
            TimeError::Law(t) => say!(
                "             e_k = {:.4e} k^{:.3} (k in {}{}, steps ×{})",
                t.c,
                t.p,
                range(&p.time_fit.x),
                orders(&p.time_fit),
                p.time_ratio
            ),
            TimeError::Bound(b) => say!(
                "             e_k ≤ {b:.3e} for every N ≥ {} (a bound from the time pilot's distances; see the note)",
                p.scene_steps
            ),
        }
        say!(
            "             e = {}",
            match m.combine {
                Combine::Quadrature => "√(e_h² + e_k²) (β ≥ 0.5: the spatial error is orthogonal to smooth fields)",
                Combine::Sum => "e_h + e_k",
            }
        );
    }
    if let Some(c) = &p.cost {
        say!(
            "Cost model:  wall = {:.3e} n^{:.3} + N · {:.3e} n ln n s (n unknowns, N steps)",
            c.setup.c,
            c.setup.p,
            c.step
        );
    }
}

fn csv_text(p: &Plan) -> String {
    let mut s = String::from(
        "role,refine,steps,unknowns,solver,tol,pred_error,space_error,time_error,pred_wall,memory,pilot_wall\n",
    );
    let mut row = |role: &str, c: &Candidate| {
        s.push_str(&format!(
            "{role},{},{},{},{},{:e},{:e},{:e},{:e},{:e},{},{:e}\n",
            c.refine,
            c.steps,
            c.unknowns,
            p.solver,
            p.tol,
            c.error,
            c.space_error,
            c.time_error,
            c.wall,
            c.memory,
            p.pilot_wall
        ));
    };
    for (i, c) in p.best.iter().enumerate() {
        row(if i == 0 { "plan" } else { "runner-up" }, c);
    }
    if let Some(c) = &p.over_budget {
        row("over-budget", c);
    }
    if p.best.is_empty() {
        s.push_str(&format!("refused,,,,,,,,,,,{:e}\n", p.pilot_wall));
    }
    s
}

/// Run the plan as the finest level of a short study at its steps (refine r−3 … r, as far as the
/// scene's mesh allows: about 1.3 times the run; four levels for the asymptotic check), whose Richardson estimate of the finest level, combined
/// with the time model at its steps, is the achieved estimate; the true error too when the scene has one.
fn execute_plan(scene: &Scene, p: &Plan, b: &Candidate) -> Result<super::summary::Achieved> {
    let mut s = scene.clone();
    s.solver.method = p.solver;
    s.solver.tol = p.tol;
    let first = b.refine.saturating_sub(3).max(scene.mesh_level());
    let levels: Vec<Level> = (first..=b.refine).map(|refine| Level { refine, steps: b.steps }).collect();
    say!("\nRunning the plan (levels {first}..={} at {} steps, for the estimate):", b.refine, b.steps);
    let study: Study = run_study(&s, &levels, None, None, |r| {
        say!("  refine {} steps {}: {:.3} s", r.refine, r.steps, r.wall);
    })?;
    let f = fit(&study, &p.options.quantity, Some(p.order_limit))?;
    let model = p.error.expect("a plan has an error model");
    let space = match (f.errors.last(), f.not_in_range()) {
        (Some(&e), None) => e,
        (_, why) => {
            note!("the run's own levels give no estimate ({}): the pilot's model is used", why.unwrap_or_default());
            model.space_error(b.h)
        }
    };
    let time = model.time_error(b.k);
    let achieved = model.combine(space, time);
    let finest = study.levels.last().expect("levels");
    say!(
        "achieved estimate {achieved:.4e} (space {space:.4e} from the run's levels, time {time:.4e} from the model) against the target {:e}: {}",
        p.options.target,
        if achieved <= p.options.target { "met" } else { "NOT met" }
    );
    if let (Quantity::Energy, Some(e)) = (&p.options.quantity, finest.max_err) {
        say!(
            "true energy error (max over the time nodes) {:.4e}: {}",
            e.energy,
            if e.energy <= p.options.target { "met" } else { "NOT met" }
        );
    }
    say!("wall of the planned level {:.3} s (predicted {:.3} s)", finest.wall, b.wall);
    Ok(super::summary::Achieved {
        estimate: achieved,
        space,
        time,
        true_error: finest.max_err.filter(|_| matches!(p.options.quantity, Quantity::Energy)).map(|e| e.energy),
        met: achieved <= p.options.target,
        levels: study.levels.iter().map(|r| super::summary::Level::of(r, None)).collect(),
    })
}

/// A duration such as 90, 90s, 250ms, 10m or 2h, in seconds.
pub fn parse_duration(text: &str) -> std::result::Result<f64, String> {
    let t = text.trim();
    let (num, unit) = t.split_at(t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len()));
    let mult = match unit {
        "" | "s" => 1.0,
        "ms" => 1e-3,
        "m" | "min" => 60.0,
        "h" => 3600.0,
        _ => return Err(format!("`{text}`: expected a duration such as 90s, 250ms, 10m or 2h")),
    };
    match num.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v * mult),
        _ => Err(format!("`{text}`: expected a positive duration such as 90s, 250ms, 10m or 2h")),
    }
}

//! `tresca-cr adapt`: the adaptive loop (solve → estimate → mark → refine over whole runs) printed as a
//! table per level and written as CSV and (`--json`) in the summary; each level's results file in `--out DIR`.

use super::out::{note, say};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tresca_cr::adapt::estimator::TERMS;
use tresca_cr::adapt::files::{level_mesh, level_results, levels_to_check};
use tresca_cr::adapt::{adapt, Options, Row};
use tresca_cr::output::guard::{write_new, Outputs};
use tresca_cr::Scene;

/// The CSV of the rows: one line per level.
pub fn csv_text(rows: &[Row], exact: bool) -> String {
    let mut s = String::from(
        "level,triangles,unknowns,paper_dofs,generation,estimator,error,error_kind,effectivity,vs_next,vs_reference,min_angle_deg,marked,wall_s,worst_step",
    );
    for t in TERMS {
        let _ = write!(s, ",eta_{t}");
    }
    s.push_str(",time_estimator,time_dissipation,time_load,estimate,richardson\n");
    for r in rows {
        let e = r.error_or_estimate();
        let f = |x: Option<f64>| x.map(|v| format!("{v:.6e}")).unwrap_or_default();
        let _ = write!(
            s,
            "{},{},{},{},{},{:.6e},{},{},{},{},{},{:.4},{},{:.4},{}",
            r.level,
            r.triangles,
            r.unknowns,
            r.paper_dofs,
            r.generation,
            r.estimator,
            f(e),
            r.error_kind(exact).unwrap_or_default(),
            f(e.map(|e| r.estimator / e)),
            f(r.vs_next),
            f(r.vs_reference),
            r.min_angle,
            r.marked,
            r.wall,
            r.worst_step
        );
        for v in r.terms {
            let _ = write!(s, ",{:.6e}", v.max(0.0).sqrt());
        }
        let _ = write!(s, ",{:.6e},{:.6e},{:.6e}", r.time_estimator, r.time_dissipation, r.time_load);
        let _ = writeln!(s, ",{},{}", f(r.estimate), f(r.richardson));
    }
    s
}

/// Refuse, before the first level, outputs that break the rule of every output (`output::guard`): the
/// level files (each level a loop may write, `adapt::files`), `--csv` and `--json`.
fn check_outputs(scene: &Scene, opts: &Options, csv: Option<&Path>, json: Option<&Path>) -> Result<()> {
    let mut outputs = Outputs::new(opts.force).inputs_of(scene).files(csv, "--csv file").files(json, "--json file");
    if let Some(dir) = &opts.out {
        outputs = outputs.dirs(Some(dir.as_path()), "--out directory");
        let others: Vec<&Path> = csv.into_iter().chain(json).collect();
        for k in levels_to_check(dir, opts.levels, &others) {
            outputs = outputs.results(&level_results(dir, k), &format!("level file of level {k}"), false);
            if opts.gmsh {
                outputs = outputs.file(&level_mesh(dir, k), &format!("Gmsh mesh of level {k}"));
            }
        }
    }
    Ok(outputs.check()?)
}

/// Run the loop and report; returns the exit code (3: stopped before the goal, with the reason).
pub fn run(scene: Scene, opts: Options, csv: Option<PathBuf>, json: Option<PathBuf>) -> Result<i32> {
    run_rows(scene, opts, csv, json).map(|(code, _)| code)
}

/// [`run`], also returning the levels' rows (for `plan --run`).
pub fn run_rows(scene: Scene, opts: Options, csv: Option<PathBuf>, json: Option<PathBuf>) -> Result<(i32, Vec<Row>)> {
    let start = std::time::Instant::now();
    check_outputs(&scene, &opts, csv.as_deref(), json.as_deref())?;
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    let exact = scene.exact.is_some();
    say!(
        "{:>5} {:>9} {:>9} {:>11} {:>11} {:>11} {:>6} {:>8} {:>7} {:>8} {:>11}",
        "level",
        "triangles",
        "unknowns",
        "estimator",
        "time est",
        if exact { "error" } else { "vs next" },
        "eff",
        "min ang",
        "marked",
        "wall s",
        "estimate"
    );
    let outcome = adapt(&scene, &opts, |r| {
        let e = r.error.map(|e| format!("{e:.4e}")).unwrap_or_else(|| "-".into());
        let eff = r.error.map(|e| format!("{:.3}", r.estimator / e)).unwrap_or_default();
        let est = r.estimate.map(|e| format!("{e:.4e}")).unwrap_or_else(|| "-".into());
        say!(
            "{:>5} {:>9} {:>9} {:>11.4e} {:>11.4e} {:>11} {:>6} {:>8.3} {:>7} {:>8.3} {:>11}",
            r.level,
            r.triangles,
            r.unknowns,
            r.estimator,
            r.time_estimator,
            e,
            eff,
            r.min_angle,
            r.marked,
            r.wall,
            est
        );
    })?;
    if !exact {
        say!("errors estimated by the distance to the next level and to the reference (effectivity against the latter, else the former):");
        say!("{:>5} {:>9} {:>11} {:>11} {:>11} {:>6}", "level", "unknowns", "estimator", "vs next", "vs ref", "eff");
        for r in &outcome.rows {
            let f = |x: Option<f64>| x.map(|v| format!("{v:.4e}")).unwrap_or_else(|| "-".into());
            let eff = r.error_or_estimate().map(|e| format!("{:.3}", r.estimator / e)).unwrap_or_default();
            say!(
                "{:>5} {:>9} {:>11.4e} {:>11} {:>11} {:>6}",
                r.level,
                r.unknowns,
                r.estimator,
                f(r.vs_next),
                f(r.vs_reference),
                eff
            );
        }
    }
    if let Some(path) = &csv {
        write_new(path, "--csv file", csv_text(&outcome.rows, exact).as_bytes(), opts.force)?;
    }
    if let Some(j) = &json {
        let mut summary = super::summary::Summary::new("adapt", &scene.file, start.elapsed().as_secs_f64());
        if let Some(why) = &outcome.stopped {
            summary.status = format!("refused: {why}");
        }
        summary.adapt = Some(super::summary::AdaptSummary::of(&opts, exact, &outcome.rows, outcome.stopped.clone()));
        super::summary::write(j, &summary, opts.force)?;
    }
    // the table is the result (or --csv keeps it): a closed or full standard output fails the command
    super::out::report_written(csv.as_deref())?;
    let code = match &outcome.stopped {
        Some(why) => {
            note!("refused: {why}");
            3
        }
        None => 0,
    };
    Ok((code, outcome.rows))
}

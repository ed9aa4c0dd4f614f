//! `tresca-cr study`: a convergence study printed as a table (and written as CSV), then the error
//! estimates without an exact solution (Richardson, GCI, asymptotic-range verdict per level).

use super::out::say;
use anyhow::{Context, Result};
use std::path::PathBuf;
use tresca_cr::output::guard::{write_new, Outputs};
use tresca_cr::scene::budget::Estimate;
use tresca_cr::study::differences::file_of;
use tresca_cr::study::richardson::Verdict;
use tresca_cr::study::{Axis, Level, LevelResult, Study};
use tresca_cr::Scene;

/// Refuse levels that make no study: one given twice, a level coarser than the one before it (in
/// refinements or steps: the estimates compare each level with the coarser ones before it), a reference
/// that is not finer than every level (its error would be 0 against itself, or the order negative).
fn check_levels(levels: &[Level], reference: Option<Level>) -> Result<()> {
    let name = |l: &Level| format!("{}:{}", l.refine, l.steps);
    for (i, l) in levels.iter().enumerate() {
        if let Some(p) = levels[..i].iter().find(|p| *p == l) {
            anyhow::bail!("--levels: the level {} is given twice", name(p));
        }
        if let Some(p) = i.checked_sub(1).map(|j| &levels[j]) {
            if l.refine < p.refine || l.steps < p.steps {
                anyhow::bail!(
                    "--levels: {} after {} is coarser (in refinements or steps); give the levels from coarse to fine",
                    name(l),
                    name(p)
                );
            }
        }
    }
    if let Some(r) = reference {
        if let Some(l) = levels.iter().find(|l| r.refine < l.refine || r.steps < l.steps || **l == r) {
            anyhow::bail!(
                "--reference {}: a reference must be finer than every level (at least the refinements and steps of \
                 each, and not one of them), but the level {} is not coarser than it",
                name(&r),
                name(l)
            );
        }
    }
    Ok(())
}

/// Refuse the study before any level is built when a level cannot fit in memory: the estimate of
/// `run`/`check` ([`Estimate`]) of the level, plus those of the two levels before it and the reference
/// run, which the study holds at the same time.
fn check_memory(scene: &Scene, levels: &[Level], reference: Option<Level>, max_memory: Option<u64>) -> Result<()> {
    let estimate = |l: Level| -> Result<Estimate> {
        let mut s = scene.clone();
        s.set_refine(l.refine)?;
        Ok(Estimate::of(&s, l.steps, false)?)
    };
    if let Some(r) = reference {
        estimate(r)?.check(max_memory, None, None).with_context(|| format!("--reference {}:{}", r.refine, r.steps))?;
    }
    let kept = reference.map(estimate).transpose()?.map_or(0, |e| e.memory);
    let each = levels.iter().map(|&l| estimate(l)).collect::<Result<Vec<_>>>()?;
    for (i, (l, e)) in levels.iter().zip(&each).enumerate() {
        let held: u64 = each[i.saturating_sub(2)..i].iter().map(|e| e.memory).sum();
        let more = |m: u64| m.saturating_add(held).saturating_add(kept);
        let together = Estimate { memory: more(e.memory), memory_metis: e.memory_metis.map(more), ..*e };
        together.check(max_memory, None, None).with_context(|| {
            format!(
                "study level {}:{} (with the levels before it and the reference it is held beside)",
                l.refine, l.steps
            )
        })?;
    }
    Ok(())
}

pub fn study(
    scene: Scene,
    levels: &[Level],
    reference: Option<Level>,
    csv: Option<PathBuf>,
    differences: Option<PathBuf>,
    max_memory: Option<u64>,
    reports: super::summary::Reports,
) -> Result<()> {
    let start = std::time::Instant::now();
    use tresca_cr::study::run_study;
    let (json, force) = (reports.json, reports.force);
    check_levels(levels, reference)?;
    let diffs: Vec<PathBuf> =
        differences.iter().flat_map(|d| levels.iter().skip(1).map(|l| file_of(d, l.refine, l.steps))).collect();
    Outputs::new(force)
        .inputs_of(&scene)
        .dirs(differences.as_deref(), "--differences directory")
        .files(csv.as_deref(), "--csv file")
        .files(json.as_deref(), "--json file")
        .files(diffs.iter().map(PathBuf::as_path), "--differences file")
        .check()?;
    check_memory(&scene, levels, reference, max_memory)?;
    say!(
        "{:>3} {:>6} {:>9} {:>9} {:>8} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>8}",
        "ref",
        "steps",
        "h",
        "k",
        "DOF",
        "energy",
        "ord",
        "L2",
        "ord",
        "consec(T)",
        "ord",
        "vs ref(T)",
        "ord",
        "wall s"
    );
    let mut prev: Option<LevelResult> = None;
    let study = run_study(&scene, levels, reference, differences.as_deref(), |r| {
        print_row(prev.as_ref(), r);
        prev = Some(r.clone());
    })?;
    say!("(energy, L2: true errors, max over each level's own time nodes)");
    print_estimates(&study);
    for f in &study.difference_files {
        say!("wrote {}", f.display());
    }
    if let Some(path) = &csv {
        write_new(path, "--csv file", tresca_cr::study::csv::text(&study).as_bytes(), force)?;
    }
    if let Some(j) = &json {
        let mut summary = super::summary::Summary::new("study", &scene.file, start.elapsed().as_secs_f64());
        summary.study = Some(super::summary::StudySummary::of(&study, reference));
        super::summary::write(j, &summary, force)?;
    }
    super::out::report_written(csv.as_deref())
}

/// The table row of level `r`, with its observed orders against the level before it (`prev`).
fn print_row(prev: Option<&LevelResult>, r: &LevelResult) {
    use tresca_cr::study::orders::observed_order;
    let o = |f: &dyn Fn(&LevelResult) -> Option<f64>| match (prev, f(r)) {
        // orders against h, or against k when only the time step changes
        (Some(p), Some(b)) => {
            let (xa, xb) = if (p.h - r.h).abs() <= 1e-12 * r.h { (p.k, r.k) } else { (p.h, r.h) };
            f(p).map(|a| format!("{:.3}", observed_order(a, b, xa, xb))).unwrap_or_default()
        }
        _ => String::new(),
    };
    let v = |x: Option<f64>| x.map(|x| format!("{x:.4e}")).unwrap_or_else(|| "-".into());
    let en = |r: &LevelResult| r.max_err.map(|e| e.energy);
    let l2 = |r: &LevelResult| r.max_err.map(|e| e.l2);
    let co = |r: &LevelResult| r.consecutive.map(|e| e[1]);
    let rf = |r: &LevelResult| r.reference.map(|e| e[1]);
    say!(
        "{:>3} {:>6} {:>9.3e} {:>9.3e} {:>8} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>8.3}",
        r.refine,
        r.steps,
        r.h,
        r.k,
        r.paper_dofs,
        v(en(r)),
        o(&en),
        v(l2(r)),
        o(&l2),
        v(co(r)),
        o(&co),
        v(rf(r)),
        o(&rf),
        r.wall
    );
}

/// The estimates: energy norm per level, then every scalar output.
fn print_estimates(s: &Study) {
    let e = &s.estimates;
    say!("");
    match (&e.model, &e.refused) {
        (Some(m), _) => say!(
            "Error estimate without an exact solution (energy norm, order in {}): p = {:.3}, β = {:.3} from the three finest levels",
            e.size, m.p, m.beta
        ),
        (None, why) => {
            say!("No error estimate (energy norm): not yet: refine further ({})", why.clone().unwrap_or_default());
        }
    }
    if e.model.is_some() {
        let true_col = s.levels.iter().any(|r| r.common_err.is_some() || r.reference.is_some());
        say!(
            "{:>3} {:>6} {:>11} {:>11} {:>11} {:>7}  verdict",
            "ref",
            "steps",
            "est(max)",
            "GCI",
            if true_col { "true/ref" } else { "" },
            if true_col { "eff" } else { "" }
        );
        for (r, l) in s.levels.iter().zip(&e.levels) {
            // the truth the estimate is compared with: the exact error on different meshes (else the
            // reference run), the reference run on one mesh (the sequence's limit is the semi-discrete solution)
            let reference = r.reference.map(|v| v[0]);
            let truth = if e.size == Axis::K { reference } else { r.common_err.map(|v| v.energy).or(reference) };
            let (t, eff) = truth
                .map_or((String::new(), String::new()), |t| (format!("{t:.4e}"), format!("{:.3}", l.error[0] / t)));
            say!(
                "{:>3} {:>6} {:>11.4e} {:>11.4e} {:>11} {:>7}  {}",
                r.refine,
                r.steps,
                l.error[0],
                l.gci,
                t,
                eff,
                l.verdict.text()
            );
        }
    }
    print_outputs(s);
}

/// A number of the outputs' table, or "—" where the study has none (no extrapolation: the line's verdict
/// says why), so that no NaN is printed as an estimate.
fn cell(v: f64, width: usize, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:>width$.digits$e}")
    } else {
        format!("{:>width$}", "—")
    }
}

/// Every scalar output: its extrapolation (or why there is none) and per level the value, estimated error
/// and GCI.
fn print_outputs(s: &Study) {
    for o in &s.outputs {
        match o.model {
            Some(m) => say!("\nOutput {} at T: extrapolated {:.6e}, p = {:.3}", o.name, m.limit, m.p),
            None => {
                let why = match o.levels.last().map(|l| &l.2) {
                    Some(Verdict::NotYet(w)) => w.clone(),
                    Some(v) => v.text(),
                    None => "no levels".into(),
                };
                say!("\nOutput {} at T: not extrapolated: {why}", o.name)
            }
        }
        let idx = s.outputs.iter().position(|x| x.name == o.name).unwrap_or(0);
        for (r, l) in s.levels.iter().zip(&o.levels) {
            say!(
                "{:>3} {:>6} value {}  est {}  GCI {}  {}",
                r.refine,
                r.steps,
                cell(r.outputs.get(idx).copied().unwrap_or(f64::NAN), 12, 5),
                cell(l.0, 10, 3),
                cell(l.1, 10, 3),
                l.2.text()
            );
        }
    }
}

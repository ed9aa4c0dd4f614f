//! `tresca-cr study`: a convergence study printed as a table (and written as CSV).

use anyhow::{Context, Result};
use std::path::PathBuf;
use tresca_cr::study::{Level, LevelResult};
use tresca_cr::Scene;

pub fn study(scene: Scene, levels: &[Level], reference: Option<Level>, csv: Option<PathBuf>) -> Result<()> {
    use tresca_cr::study::orders::observed_order;
    use tresca_cr::study::{csv_row, run_study, CSV_HEADER};
    println!(
        "{:>3} {:>6} {:>9} {:>9} {:>8} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>8}",
        "ref", "steps", "h", "k", "DOF", "energy", "ord", "L2", "ord", "consec(T)", "ord", "vs ref(T)", "ord", "wall s"
    );
    let mut prev: Option<LevelResult> = None;
    let results = run_study(&scene, levels, reference, |r| {
        let o = |f: &dyn Fn(&LevelResult) -> Option<f64>| match (&prev, f(r)) {
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
        println!(
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
        prev = Some(r.clone());
    })?;
    if let Some(path) = csv {
        let mut text = String::from(CSV_HEADER);
        text.push('\n');
        for r in &results {
            text += &csv_row(r);
            text.push('\n');
        }
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

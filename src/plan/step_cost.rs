//! The cost of a step on a second mesh (issue 42): the time pilot measures the seconds per step on one
//! coarse mesh, where a fixed per-step overhead (the expression evaluation's threads, the friction
//! solve's set-up, the bookkeeping of a step) is a large share of a step; scaled as n ln n to a plan three
//! refinements finer it over-predicted the plan's steps (mms_data_front, refine 2 → 5: 1.6×). One more
//! run of the scene's steps on the next finer mesh, the space pilot's level there (its set-up shared),
//! gives a second per-step sample where that overhead weighs four times less. The law and why the
//! smallest implied constant over both meshes is the right fit of it: [`super::model::CostModel::fit`].

use super::pilot::Runner;
use crate::error::Result;
use crate::scene::Scene;
use crate::study::{Level, LevelResult, SetupCache};

/// The per-step sample on mesh `refine` (where the space pilot, on `nh` steps per level, has run): the
/// space pilot's own level when it runs at least the scene's `n0` steps (then it costs nothing more),
/// else half the scene's steps (a multiple of `nh`, which then divides `n0` by a power of two: long
/// enough that the first steps' extra iterations add a few per cent, at half the cost of `n0`). Returns the level (none when `budget` seconds do not allow its `predicted`
/// cost), the seconds it took, and a note saying so.
pub(crate) fn second_mesh(
    s: &Scene,
    (refine, nh, n0): (u32, usize, usize),
    cache: &SetupCache,
    predicted: f64,
    budget: f64,
) -> Result<(Vec<LevelResult>, f64, String)> {
    // on the space pilot's common nodes: its level there is handed over when it has these steps
    let mut run = Runner::new(s, nh, cache)?;
    let steps = if nh >= n0 { nh } else { (n0 / 2).max(nh) };
    if let Some(why) = run.push(Level { refine, steps }, predicted, budget)? {
        return Ok((vec![], 0.0, format!("the cost of a step is measured on the time pilot's mesh only: {why}")));
    }
    let level = run.levels()[0].clone();
    let spent = run.spent;
    let note = format!(
        "the cost of a step is also measured on refine {refine} ({} unknowns, {steps} steps: {:.3e} s per step; {:.3} s \
         of pilot)",
        level.dofs,
        (level.wall - level.setup).max(0.0) / steps as f64,
        spent
    );
    Ok((vec![level], spent, note))
}

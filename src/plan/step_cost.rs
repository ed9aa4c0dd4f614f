//! The cost of a step as `tresca-cr run` pays it, timed on the time pilot's mesh.
//!
//! A pilot level is a study's level: it forms u at the sequence's common nodes and audits no energy (save
//! with boundary data), and its wall holds the study's own work per step. A run without a results file
//! and without true errors forms u at its last step only and audits the energy of every step. The two
//! differ per step both ways (a pilot step cost 0.13–1.6× a run's on the same mesh over the cost
//! bench's scenes), so the per-step constant c of s(n) = c n ln n ([`super::model::CostModel`]) is
//! taken from runs on the run's own path ([`RunOptions`] as `tresca-cr run` sets them): [`REPEATS`]
//! runs of the time pilot's longest grid on its mesh, whose set-up the pilot's cache already holds,
//! timed from the hand-over of step 0 (which a run computes with its set-up) to the last step: on the
//! scenes' few steps (4 on mms_stop) step 0 would otherwise be most of the sample. Each gives a sample and the cost model keeps the smallest
//! (`super::model` module doc, "Why minima": noise only slows a timing down).
//!
//! The timed runs count against the pilot budget: a run starts only if the level's own time fits in what
//! is left. Where none fits, the model takes the level's own steps, as it did before these runs.
//!
//! What the prediction then covers: the printed command on a scene without `[exact]` and `[output]`.
//! True errors (formed at every step with `[exact]`) and a results file add to the steps' cost.

use super::model::CostSample;
use crate::error::Result;
use crate::scene::Scene;
use crate::stepping::RunOptions;
use crate::study::{LevelResult, SetupCache};
use std::time::Instant;

/// Timed runs of the scene's steps; the smallest per-step cost is the model's.
pub const REPEATS: usize = 3;

/// Up to [`REPEATS`] per-step samples (with their steps, for [`super::model::CostModel::fit`]) of `scene`
/// on the mesh and grid of the pilot level `level`, run as `tresca-cr run` runs without a results file or
/// true errors, and the seconds they took in all. A run is started only while the seconds spent plus
/// `expected` (the level's own time after its set-up) stay within `budget`: none where the pilot budget
/// has no room left, and the caller falls back to the level's own steps.
pub fn run_steps(
    scene: &Scene,
    level: &LevelResult,
    expected: f64,
    budget: f64,
    cache: &SetupCache,
) -> Result<(Vec<(CostSample, usize)>, f64)> {
    let (refine, steps) = (level.refine, level.steps);
    let mut s = scene.clone();
    s.set_refine(refine)?;
    s.set_steps(steps)?;
    s.exact = None;
    let mut samples = Vec::with_capacity(REPEATS);
    let mut spent = 0.0;
    while samples.len() < REPEATS && spent + expected <= budget {
        let problem = cache.problem(s.clone(), refine)?;
        let last = problem.n_steps();
        let begun = Instant::now();
        // from the hand-over of step 0 (computed with the set-up in a run) to the last step
        let mut start = None;
        problem.run(RunOptions { after: None, want: |k| k == last, audit: true }, |r| {
            if r.n == 0 {
                start = Some(Instant::now());
            }
            Ok(())
        })?;
        let wall = start.map_or(0.0, |t| t.elapsed().as_secs_f64());
        spent += begun.elapsed().as_secs_f64();
        let n = problem.space.n_dofs as f64;
        samples.push((CostSample { n, setup: 0.0, step: wall / last.max(1) as f64 }, last));
    }
    Ok((samples, spent))
}

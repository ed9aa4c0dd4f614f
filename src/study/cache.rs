//! Factor once per mesh: the set-ups ([`MeshSetUp`]) of the meshes a study or a plan runs, by
//! refinement level, shared by its levels on the same mesh (a k-study's levels, the planner's time
//! pilot and the space pilot's level on the same mesh). A cache belongs to one scene: its levels differ
//! from it only in refinement and steps, so the refinement alone names the mesh.
//!
//! It keeps the set-ups of several meshes while they hold at most [`SHARE_OF_MEMORY`] of the memory
//! available when a set-up is added (the newest is always kept): the planner returns to its pilot
//! meshes, and studies usually hold one mesh at a time. Which set-ups it keeps only changes speed:
//! a shared set-up has the values of a fresh one.
//!
//! It also keeps the finished levels of sequences that share runs (the planner's pilots,
//! [`super::Sequence::sharing_runs`]): a level (mesh, steps) run by one pilot sequence with the same
//! common time nodes is handed to the next instead of run again (the time pilot's ×4 grids after its
//! doubling grids, the space pilot's level on the time pilot's mesh and grid). A kept run has the values
//! of a fresh one (the same set-up and steps); its runs are dropped with its mesh's set-up.

use super::measure::Kept;
use super::{Level, LevelResult};
use crate::error::Result;
use crate::scene::budget::available_memory;
use crate::scene::Scene;
use crate::stepping::{Guard, MeshSetUp, Problem, SetupTimes};
use std::sync::{Arc, Mutex};

/// At most this share of the available memory is kept in set-ups other than the newest.
const SHARE_OF_MEMORY: f64 = 0.25;

/// Shared handle (clones share the cache) on the set-ups of one scene's meshes.
#[derive(Clone, Default)]
pub struct SetupCache {
    inner: Arc<Mutex<Inner>>,
}

#[derive(Default)]
struct Inner {
    /// Set-ups by refinement, oldest first.
    entries: Vec<(u32, Arc<MeshSetUp>)>,
    /// Set-ups made, by refinement (a mesh made twice was dropped in between).
    made: Vec<u32>,
    /// Problems handed out.
    problems: usize,
    /// Finished levels kept for sequences sharing runs, with their sequence's number of common steps.
    runs: Vec<(Level, usize, LevelResult, Arc<Kept>)>,
    /// Levels run (refinement, steps, common steps), in order: each solve of the steps.
    solved: Vec<(u32, usize, usize)>,
    /// Estimate K's condition number on the first mesh only ([`SetupCache::guard_first_mesh_only`]).
    guard_first_only: bool,
    /// Set-ups made with the condition estimate, by refinement.
    guarded: Vec<u32>,
}

impl SetupCache {
    /// The problem of `scene` (at refinement `refine`): on the cached set-up of that mesh, made first if
    /// there is none ([`Problem::on_shared`]).
    /// The problem that made the set-up reports its phases as its own (`reused` is `None`).
    pub fn problem(&self, scene: Scene, refine: u32) -> Result<Problem> {
        let (shared, made) = self.set_up(&scene, refine)?;
        self.lock().problems += 1;
        let mut p = Problem::on_shared(scene, &shared)?;
        if made {
            p.setup = SetupTimes { superposition: p.setup.superposition, ..shared.times() };
            p.reused = None;
        }
        Ok(p)
    }

    /// The set-up of the mesh at `refine`, and whether it was made now.
    fn set_up(&self, scene: &Scene, refine: u32) -> Result<(Arc<MeshSetUp>, bool)> {
        if let Some((_, m)) = self.lock().entries.iter().find(|(r, _)| *r == refine) {
            return Ok((Arc::clone(m), false));
        }
        let guard = {
            let inner = self.lock();
            if inner.guard_first_only && !inner.made.is_empty() {
                Guard::Skip
            } else {
                Guard::Estimate
            }
        };
        let m = Arc::new(MeshSetUp::new(scene, guard)?);
        let mut inner = self.lock();
        inner.made.push(refine);
        if guard == Guard::Estimate {
            inner.guarded.push(refine);
        }
        inner.entries.push((refine, Arc::clone(&m)));
        let limit = available_memory().map_or(0.0, |a| a as f64 * SHARE_OF_MEMORY);
        while inner.entries.len() > 1
            && inner.entries[..inner.entries.len() - 1].iter().map(|(_, m)| m.bytes() as f64).sum::<f64>() > limit
        {
            let (r, _) = inner.entries.remove(0);
            inner.runs.retain(|(l, ..)| l.refine != r);
        }
        Ok((m, true))
    }

    /// A finished level of a sequence with `common` common steps, if one was kept ([`SetupCache::keep_run`]).
    pub(crate) fn kept_run(&self, level: Level, common: usize) -> Option<(LevelResult, Arc<Kept>)> {
        let inner = self.lock();
        let found = inner.runs.iter().find(|(l, c, ..)| *l == level && *c == common);
        found.map(|(_, _, r, k)| (r.clone(), Arc::clone(k)))
    }

    /// Count a level run (refinement, steps) of a sequence with `common` common steps.
    pub(crate) fn count_run(&self, level: Level, common: usize) {
        self.lock().solved.push((level.refine, level.steps, common));
    }

    /// Keep a finished level for later sequences sharing runs, while its mesh's set-up is kept and the
    /// kept unknowns hold at most [`SHARE_OF_MEMORY`] / 2 of the available memory.
    pub(crate) fn keep_run(&self, level: Level, common: usize, result: &LevelResult, kept: &Arc<Kept>) {
        let mut inner = self.lock();
        if !inner.entries.iter().any(|(r, _)| *r == level.refine) {
            return;
        }
        let bytes = |k: &Kept| k.u.iter().map(|u| 8 * u.len()).sum::<usize>();
        let held: usize = inner.runs.iter().map(|(.., k)| bytes(k)).sum::<usize>() + bytes(kept);
        let limit = available_memory().map_or(0.0, |a| a as f64 * SHARE_OF_MEMORY / 2.0);
        if held as f64 <= limit {
            inner.runs.push((level, common, result.clone(), Arc::clone(kept)));
        }
    }

    /// The levels run so far (refinement, steps, common steps), in order; a level handed from a kept
    /// run is not run again and not listed again.
    pub fn solved(&self) -> Vec<(u32, usize, usize)> {
        self.lock().solved.clone()
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Inner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Make the condition estimate (the guard against a nearly singular K, `stepping::conditioning`) on
    /// the first mesh set up only: a planner's pilots, whose walls model the planned run's cost and whose
    /// first mesh (the time pilot's) is where the guard refuses a scene; the planned run checks its own K.
    pub fn guard_first_mesh_only(&self) {
        self.lock().guard_first_only = true;
    }

    /// Set-ups made so far (assemblies and numeric factorisations of K), by refinement, in order.
    pub fn factorised(&self) -> Vec<u32> {
        self.lock().made.clone()
    }

    /// Set-ups made with the condition estimate so far, by refinement, in order.
    pub fn guarded(&self) -> Vec<u32> {
        self.lock().guarded.clone()
    }

    /// Problems handed out so far (one per level run).
    pub fn problems(&self) -> usize {
        self.lock().problems
    }
}

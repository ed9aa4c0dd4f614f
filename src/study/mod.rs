//! Convergence studies: one scene run at a list of levels (refinement, number of steps), with
//!
//! * true errors when the scene has an exact solution: the max over each level's own time nodes ("max
//!   over n", the paper's ℓ∞(0,T) norm), the max over the nodes common to all levels, and at T,
//! * the distances between levels ([`measure`]): the paper's consecutive-level error, the error against
//!   a finer reference run, and the distances of the Richardson model,
//! * error estimates without an exact solution ([`estimate`] for the energy norm, [`outputs`] for
//!   scalar outputs, both on [`richardson`]) with GCIs and an asymptotic-range verdict per level,
//!
//! distances at the common time nodes — the nodes of the coarsest time grid — where alone u is kept, so
//! long runs stay cheap (with an exact solution u is formed at every node for the true errors).

pub mod cache;
pub mod contact_states;
pub mod csv;
pub mod differences;
pub mod estimate;
pub mod measure;
pub mod orders;
pub mod outputs;
pub mod richardson;

use crate::error::{Error, Result};
use crate::fem::norms::ErrorNorms;
use crate::names::named_enum;
use crate::scene::Scene;
use crate::stepping::{RunOptions, StepResult};
pub use cache::SetupCache;
use measure::{max_last, Kept};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

named_enum! {
    /// The axis a sequence of levels refines: the mesh size h, or the time step k on one mesh.
    pub enum Axis {
        /// The mesh size (the levels' meshes differ).
        H = "h",
        /// The time step (all levels on one mesh).
        K = "k",
    }
}

/// A level: uniform refinements and number of uniform time steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Level {
    pub refine: u32,
    pub steps: usize,
}

impl std::str::FromStr for Level {
    type Err = String;
    /// `refine:steps`, e.g. `3:320`.
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        let (r, n) = s.split_once(':').ok_or_else(|| format!("level `{s}`: expected refine:steps, e.g. 2:160"))?;
        let refine = r.trim().parse().map_err(|_| format!("level `{s}`: bad refine `{r}`"))?;
        let steps = n.trim().parse().map_err(|_| format!("level `{s}`: bad steps `{n}`"))?;
        if steps == 0 {
            return Err(format!("level `{s}`: steps must be at least 1"));
        }
        Ok(Level { refine, steps })
    }
}

/// Results of one level.
#[derive(Clone, Debug, Default)]
pub struct LevelResult {
    pub refine: u32,
    pub steps: usize,
    pub h: f64,
    pub k: f64,
    pub dofs: usize,
    pub paper_dofs: usize,
    /// Wall time of the level: set-up and steps (seconds).
    pub wall: f64,
    /// The set-up part of `wall` (mesh, assembly, factorisation, condensation; with a set-up shared with
    /// an earlier level on the same mesh, only the load superposition).
    pub setup: f64,
    /// Whether this level assembled and factorised K (false: it shared the set-up of an earlier level on
    /// the same mesh, [`SetupCache`]).
    pub factorised: bool,
    /// Seconds of set-up shared from that earlier level (0 when factorised): `setup` plus this is the
    /// set-up of a run of the level alone.
    pub reused_setup: f64,
    /// Whether the level was handed from an earlier sequence's run of it ([`SetupCache`], a plan's
    /// pilots): not run again, its times are that run's.
    pub shared_run: bool,
    pub iterations: usize,
    /// True errors, max over the level's own time nodes ("max over n").
    pub max_err: Option<ErrorNorms>,
    /// True errors, max over the time nodes common to all levels.
    pub common_err: Option<ErrorNorms>,
    /// True errors at the final time.
    pub final_err: Option<ErrorNorms>,
    /// max over the common nodes of the solution's discrete energy norm a_h(u, u)^{1/2}.
    pub norm_max: f64,
    /// Consecutive-level error: max over common nodes, and at the final time.
    pub consecutive: Option<[f64; 2]>,
    /// Error against the reference run: max over common nodes, and at the final time.
    pub reference: Option<[f64; 2]>,
    /// Model distance to the previous level, per common node ([`measure::distance`]).
    pub increment: Option<Vec<f64>>,
    /// Model distance to the level two back, per common node.
    pub skip: Option<Vec<f64>>,
    /// Own jump energy per common node ([`measure::jumps`]).
    pub jumps: Vec<f64>,
    /// Scalar outputs at T ([`outputs`]).
    pub outputs: Vec<f64>,
    /// The contact states seen over all steps at each vertex of Γ_C ([`contact_states`]).
    pub contact_states: Vec<([f64; 2], u8)>,
}

/// A finished study: the levels, the energy-norm estimates and the output estimates.
#[derive(Clone, Debug)]
pub struct Study {
    pub levels: Vec<LevelResult>,
    pub estimates: estimate::Estimates,
    pub output_names: Vec<String>,
    pub outputs: Vec<outputs::OutputEstimate>,
    /// Files written by `--differences`.
    pub difference_files: Vec<PathBuf>,
}

/// Run one level; `own_nodes`: form u at every node for the true errors' max over the level's own nodes
/// (else only at the common nodes, as for a reference run).
fn run_level(
    scene: &Scene,
    cache: &SetupCache,
    level: Level,
    common: &[f64],
    own_nodes: bool,
    out: &mut LevelResult,
) -> Result<Kept> {
    let mut s = scene.clone();
    s.set_refine(level.refine)?;
    s.set_steps(level.steps)?;
    let start = Instant::now();
    let problem = cache.problem(s, level.refine)?;
    let (mut u, mut kept_t) = (Vec::new(), Vec::new());
    let (mut max_err, mut common_err, mut final_err) = (None::<ErrorNorms>, None::<ErrorNorms>, None);
    let (mut iterations, mut norm_max) = (0, 0.0f64);
    let times = &problem.scene.times;
    let is_common: Vec<bool> =
        times.iter().map(|&s| common.iter().any(|&t| (t - s).abs() <= 1e-12 * t.abs().max(1.0))).collect();
    // with an exact solution u is formed at every node, for the max over the level's own nodes
    let all = own_nodes && problem.scene.exact.is_some();
    let names = outputs::selected(scene);
    let mut values = Vec::new();
    let mut seen = contact_states::Seen::default();
    let first = problem.initial()?;
    let last_n = times.len() - 1;
    let mut on_step = |r: &StepResult| -> Result<()> {
        iterations += r.iterations;
        seen.record(&problem.space, r);
        if let Some(e) = r.errors {
            let mx = |m: Option<ErrorNorms>| Some(m.map_or(e, |m| m.max(e)));
            max_err = mx(max_err);
            if is_common[r.n] {
                common_err = mx(common_err);
            }
            final_err = Some(e);
        }
        if is_common[r.n] {
            norm_max = norm_max.max(r.energy.max(0.0).sqrt());
            u.push(r.u.clone());
            kept_t.push(r.t);
        }
        if r.n == last_n {
            values = outputs::values(&names, &problem, r);
        }
        Ok(())
    };
    on_step(&first)?;
    // no energy audit: a study reports none (with boundary data it runs anyway, for the steps' energy)
    problem.run(RunOptions { after: Some(first), want: |n| all || is_common[n], audit: false }, &mut on_step)?;
    if u.len() != common.len() {
        return Err(Error::scene(
            &scene.file,
            "study",
            format!("level {}:{} misses common time nodes", level.refine, level.steps),
        ));
    }
    *out = LevelResult {
        refine: level.refine,
        steps: level.steps,
        h: problem.mesh.h_max(),
        k: times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max),
        dofs: problem.space.n_dofs,
        paper_dofs: problem.space.paper_dofs(),
        wall: start.elapsed().as_secs_f64(),
        setup: problem.setup.as_array().iter().sum(),
        factorised: problem.reused.is_none(),
        reused_setup: problem.reused.map_or(0.0, |t| t.as_array().iter().sum()),
        iterations,
        max_err,
        common_err,
        final_err,
        norm_max,
        outputs: values,
        contact_states: seen.at_vertices(&problem.mesh, &problem.space),
        ..LevelResult::default()
    };
    Ok(Kept { problem, u, t: kept_t })
}

/// A study under way: levels are added one at a time ([`Sequence::push`]), each compared with the two
/// before it, then [`Sequence::finish`] estimates the errors. Levels must share the time nodes of the
/// coarsest grid (`common`: e.g. steps doubling, or all levels with the same steps).
pub struct Sequence<'a> {
    scene: &'a Scene,
    /// The set-ups of the meshes run, shared by the levels on one mesh.
    cache: SetupCache,
    common: Vec<f64>,
    reference: Option<Kept>,
    differences: Option<&'a Path>,
    difference_files: Vec<PathBuf>,
    results: Vec<LevelResult>,
    prev: Option<Arc<Kept>>,
    prev2: Option<Arc<Kept>>,
    /// Take levels from, and keep them in, the cache's runs ([`Sequence::sharing_runs`]).
    share_runs: bool,
    /// Measure the paper's consecutive-level error |||u_l − P u_{l−1}||| (reported by studies; the
    /// planner does not use it).
    consecutive: bool,
}

impl<'a> Sequence<'a> {
    /// A sequence whose common time nodes are those of `min_steps` uniform steps, with an optional
    /// reference run and, with `differences`, the elementwise energy density of u_l − P u_{l−1} of every
    /// level l ≥ 2 written there ([`differences`]).
    pub fn new(
        scene: &'a Scene,
        min_steps: usize,
        reference: Option<Level>,
        differences: Option<&'a Path>,
    ) -> Result<Sequence<'a>> {
        Sequence::with_cache(scene, min_steps, reference, differences, SetupCache::default())
    }

    /// As [`Sequence::new`], with the levels' set-ups taken from (and added to) `cache`, which must
    /// hold set-ups of `scene`'s meshes only.
    pub fn with_cache(
        scene: &'a Scene,
        min_steps: usize,
        reference: Option<Level>,
        differences: Option<&'a Path>,
        cache: SetupCache,
    ) -> Result<Sequence<'a>> {
        if !scene.uniform_time {
            return Err(Error::scene(
                &scene.file,
                "time",
                "a study needs `T` and `steps` (uniform grids), not `times`",
            ));
        }
        let (t0, t1) = (scene.times[0], *scene.times.last().expect("nodes"));
        let common: Vec<f64> = (0..=min_steps).map(|i| t0 + (t1 - t0) * i as f64 / min_steps as f64).collect();
        let reference = match reference {
            Some(l) => Some(run_level(scene, &cache, l, &common, false, &mut LevelResult::default())?),
            None => None,
        };
        Ok(Sequence {
            scene,
            cache,
            common,
            reference,
            differences,
            difference_files: vec![],
            results: vec![],
            prev: None,
            prev2: None,
            share_runs: false,
            consecutive: true,
        })
    }

    /// The sequence taking a level from the cache when an earlier sequence with the same common time
    /// nodes ran it, and keeping its levels there for later ones ([`SetupCache`]: the planner's pilots).
    pub fn sharing_runs(mut self) -> Self {
        self.share_runs = true;
        self
    }

    /// The sequence without the paper's consecutive-level error (a prolongation and an energy norm at
    /// every common node of every level, which only studies report).
    pub fn without_consecutive(mut self) -> Self {
        self.consecutive = false;
        self
    }

    /// Run one more level and compare it with the previous two (and the reference run).
    pub fn push(&mut self, level: Level) -> Result<&LevelResult> {
        let common = self.common.len() - 1;
        let (mut r, kept) = match self.cache.kept_run(level, common).filter(|_| self.share_runs) {
            Some((r, kept)) => (LevelResult { shared_run: true, ..r }, kept),
            None => {
                let mut r = LevelResult::default();
                // the pilots of a plan run one after the other on one thread: the Arc is for the cache's
                // Mutex, never sent to another thread
                #[allow(clippy::arc_with_non_send_sync)]
                let kept = Arc::new(run_level(self.scene, &self.cache, level, &self.common, true, &mut r)?);
                self.cache.count_run(level, common);
                r.jumps = measure::jumps(&kept)?;
                if self.share_runs {
                    self.cache.keep_run(level, common, &r, &kept);
                }
                (r, kept)
            }
        };
        if let Some(p) = &self.prev {
            if self.consecutive {
                r.consecutive = Some(max_last(&measure::consecutive(&kept, p)?));
            }
            r.increment = Some(measure::distance(&kept, p)?);
            if let Some(dir) = self.differences {
                self.difference_files.push(differences::write(dir, &kept, p)?);
            }
        }
        if let Some(p2) = &self.prev2 {
            r.skip = Some(measure::distance(&kept, p2)?);
        }
        if let Some(rf) = &self.reference {
            r.reference = Some(max_last(&measure::reference_error(rf, &kept)?));
        }
        self.results.push(r);
        self.prev2 = self.prev.take();
        self.prev = Some(kept);
        Ok(self.results.last().expect("just pushed"))
    }

    /// The scene the levels are run from.
    pub fn scene(&self) -> &Scene {
        self.scene
    }

    /// The levels run so far.
    pub fn levels(&self) -> &[LevelResult] {
        &self.results
    }

    /// The study of the levels run so far, with its error estimates.
    pub fn finish(&self) -> Study {
        let names = outputs::names(&outputs::selected(self.scene));
        let (size, x) = estimate::sizes(&self.results);
        let q: Vec<Vec<f64>> = self.results.iter().map(|r| r.outputs.clone()).collect();
        Study {
            estimates: estimate::estimate(&self.results),
            outputs: outputs::estimate(&names, size, &x, &q),
            output_names: names,
            levels: self.results.clone(),
            difference_files: self.difference_files.clone(),
        }
    }
}

/// Run the study of `levels` ([`Sequence`]), reporting each level as it finishes.
pub fn run_study(
    scene: &Scene,
    levels: &[Level],
    reference: Option<Level>,
    differences: Option<&Path>,
    mut report: impl FnMut(&LevelResult),
) -> Result<Study> {
    let n0 = levels.iter().map(|l| l.steps).min().ok_or_else(|| Error::scene(&scene.file, "study", "no levels"))?;
    let mut seq = Sequence::new(scene, n0, reference, differences)?;
    for &level in levels {
        report(seq.push(level)?);
    }
    Ok(seq.finish())
}

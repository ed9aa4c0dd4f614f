//! Adaptive meshes: the loop solve → estimate → mark → refine over whole runs (one mesh for the whole
//! time interval, refined between runs).
//!
//! Level 0 is the scene's mesh (with its `refine`), each triangle labelled for newest-vertex bisection
//! by its longest side (`mesh::bisect`). Each level runs every time step, computes the indicator of
//! every node ([`estimator`]), keeps per triangle its max over the nodes, marks by Dörfler's rule with
//! θ, bisects with completion and goes on — until `levels` levels are done or the error estimate is at
//! most the target (from level `estimate::TRUSTED_FROM` on). Each level reports its unknowns, estimator, the true error (max over the nodes) when
//! the scene has `[exact]`, else, once the next level is solved, the distance to it (the `study`-style
//! estimate: |||u_{k+1} − u_k||| as `study::measure::reference_error` measures it), the minimum angle
//! and the wall time. Before a level is set up its memory (and results file) are estimated from the
//! built mesh and refused when they do not fit, as `run` does; with a wall-time budget a level is
//! refused when the time so far plus the last level's time scaled by the growth in unknowns exceeds it.
//! Beside η each level reports the time indicator η_k ([`time`]), a bound on the error of the time
//! stepping (the steps are the scene's; the loop refines space only), and from level 1 on the error
//! estimate ([`estimate`]: η calibrated against a Richardson estimate along the sequence in N).

pub mod estimate;
pub mod estimator;
pub mod export;
pub mod files;
pub mod reference;
pub mod time;

use crate::error::{Error, Result};
use crate::mesh::bisect::{bisect, dorfler, label_longest_edge};
use crate::mesh::{raw_from_spec, Mesh};
use crate::output::{Run, Writer};
use crate::scene::budget::Estimate;
use crate::scene::Scene;
use crate::stepping::{Problem, StepResult};
use estimator::{Accumulated, Estimator};
use reference::{distance, increments, overlay, Kept};
use std::path::PathBuf;
use std::time::Instant;
use time::TimeIndicator;

/// What the adaptive loop is asked to do.
#[derive(Clone, Debug)]
pub struct Options {
    /// Number of levels (solves), level 0 included.
    pub levels: Option<usize>,
    /// Stop once the error estimate ([`estimate`]) is at most this, from level `estimate::TRUSTED_FROM`
    /// on (the indicator η overestimates the error by a factor 2–7 that differs between scenes and routes).
    pub target: Option<f64>,
    /// Stop once a level has at least this many unknowns.
    pub until_unknowns: Option<usize>,
    /// Dörfler's θ in (0, 1].
    pub theta: f64,
    /// Write `level_<k>.h5` here.
    pub out: Option<PathBuf>,
    /// Also write each level's mesh as `level_<k>.msh` (Gmsh 4.1) into `out`.
    pub gmsh: bool,
    pub force: bool,
    pub max_memory: Option<u64>,
    pub max_disk: Option<u64>,
    /// Wall-time budget of the whole loop, seconds.
    pub budget: Option<f64>,
    /// Measure every level against a reference: the finest level's mesh refined to at least this
    /// generation ([`reference::overlay`]).
    pub reference: Option<u32>,
    /// A planner's pilot (`plan::adaptive`): only η, the error estimate and the unknowns are read, so no
    /// energy audit, no time indicator and no condition estimate (the uniform pilots made it) are computed
    /// (those fields of the rows stay 0).
    pub lean: bool,
}

impl Options {
    /// `levels` levels with Dörfler's θ, nothing written, no limit but the machine's.
    pub fn levels(levels: usize, theta: f64) -> Options {
        Options {
            levels: Some(levels),
            target: None,
            until_unknowns: None,
            theta,
            out: None,
            gmsh: false,
            force: false,
            max_memory: None,
            max_disk: None,
            budget: None,
            reference: None,
            lean: false,
        }
    }
}

/// One level's figures.
#[derive(Clone, Debug, Default)]
pub struct Row {
    pub level: usize,
    pub triangles: usize,
    pub unknowns: usize,
    pub paper_dofs: usize,
    /// Edges on the contact parts.
    pub contact_edges: u64,
    /// η = max over the nodes of (Σ_T η_T²)^{1/2}.
    pub estimator: f64,
    /// The squared terms of η at its worst node (`estimator::TERMS`) and that node.
    pub terms: [f64; 5],
    pub worst_step: usize,
    /// True energy error, max over the nodes (with `[exact]`).
    pub error: Option<f64>,
    /// Distance to the next level (max over the nodes), known once it is solved.
    pub vs_next: Option<f64>,
    /// Distance to the reference solution (with [`Options::reference`]).
    pub vs_reference: Option<f64>,
    /// Largest bisection generation of a triangle.
    pub generation: u32,
    pub min_angle: f64,
    pub marked: usize,
    pub wall: f64,
    /// The time indicator η_k = D^{1/2} + 3L ([`time`]) and its two parts D^{1/2} and L.
    pub time_estimator: f64,
    pub time_dissipation: f64,
    pub time_load: f64,
    /// R_k, the Richardson estimate along the sequence from this level and the one before, and E_k, the
    /// error estimate: η calibrated against the R of the last levels ([`estimate`]); from level 1 on.
    pub richardson: Option<f64>,
    pub estimate: Option<f64>,
}

impl Row {
    /// The error the estimator is compared with: the true one, else the distance to the reference,
    /// else to the next level.
    pub fn error_or_estimate(&self) -> Option<f64> {
        self.error.or(self.vs_reference).or(self.vs_next)
    }

    /// What [`Row::error_or_estimate`] is: `true` (`exact`: the scene has `[exact]`), `vs_reference` or
    /// `vs_next`; `None` when no error is known.
    pub fn error_kind(&self, exact: bool) -> Option<&'static str> {
        self.error_or_estimate()?;
        Some(if exact {
            "true"
        } else if self.vs_reference.is_some() {
            "vs_reference"
        } else {
            "vs_next"
        })
    }
}

/// A solved level: its fields at every node, the accumulated indicator, the true error.
struct Solved {
    kept: Kept,
    acc: Accumulated,
    error: Option<f64>,
    time: TimeIndicator,
    unknowns: usize,
    paper_dofs: usize,
}

/// The finished loop: the rows and, if it stopped before its goal, why.
pub struct Outcome {
    pub rows: Vec<Row>,
    pub stopped: Option<String>,
}

/// The labelled starting mesh of `scene`.
pub fn initial_mesh(scene: &Scene) -> Result<Mesh> {
    let mut raw = raw_from_spec(&scene.mesh)?;
    label_longest_edge(&mut raw);
    Mesh::build(raw)
}

/// Solve every step of `scene` on `mesh`, with the indicator at every node (and the time indicator
/// with `timed`; the energy audit and the fields at every node kept unless `lean`); write the results
/// file.
fn solve(scene: &Scene, mesh: Mesh, out: Option<PathBuf>, force: bool, timed: bool, lean: bool) -> Result<Solved> {
    // a lean pilot follows the planner's uniform pilots, whose first mesh had the condition estimate
    let guard = if lean { crate::stepping::Guard::Skip } else { crate::stepping::Guard::Estimate };
    let problem = Problem::with_mesh_guarded(scene.clone(), mesh, guard)?;
    let est = Estimator::new(&problem)?;
    let mut writer = match &out {
        Some(p) => Some(Writer::create(p, &Run::of(&problem), force)?),
        None => None,
    };
    let (mut acc, mut u, mut t, mut error) = (Accumulated::default(), Vec::new(), Vec::new(), None::<f64>);
    let mut time = TimeIndicator::default();
    let mut on_step = |r: &StepResult| -> Result<()> {
        acc.push(r.n, &est.at(&problem, r)?);
        if timed {
            time.push(&problem, r)?;
        }
        if let Some(e) = r.errors {
            error = Some(error.map_or(e.energy, |m| m.max(e.energy)));
        }
        if let Some(w) = writer.as_mut() {
            w.write_step(r)?;
        }
        u.push(r.u.clone());
        t.push(r.t);
        Ok(())
    };
    let options = crate::stepping::RunOptions { audit: !lean, ..crate::stepping::RunOptions::all() };
    let result = problem.run(options, &mut on_step);
    let status = result.as_ref().map_or_else(|e| format!("stopped: {e}"), |()| "completed".to_string());
    if let Some(w) = writer {
        w.finish(&status)?;
    }
    result?;
    let (unknowns, paper_dofs) = (problem.space.n_dofs, problem.space.paper_dofs());
    let parts = problem.scene.parts.clone();
    let (mesh, space, data) = (problem.mesh.clone(), problem.space.clone(), problem.data.clone());
    let kept = Kept { mesh, space, data, u, t, parts };
    Ok(Solved { kept, acc, error, time, unknowns, paper_dofs })
}

/// Number of contact edges of `mesh` under `scene`'s parts.
fn contact_edges(scene: &Scene, mesh: &Mesh) -> u64 {
    let contact: Vec<&str> = scene
        .parts
        .iter()
        .filter(|p| matches!(p.kind, crate::scene::PartKind::Contact(..)))
        .map(|p| p.name.as_str())
        .collect();
    mesh.edge_tag.iter().flatten().filter(|&&t| contact.contains(&mesh.tag_names[t].as_str())).count() as u64
}

/// Run the adaptive loop; `report` sees each row as soon as its level is solved (the row of level k
/// again, with `vs_next` and `vs_reference`, is in the outcome).
pub fn adapt(scene: &Scene, opts: &Options, mut report: impl FnMut(&Row)) -> Result<Outcome> {
    if !(opts.theta > 0.0 && opts.theta <= 1.0) {
        return Err(Error::scene(&scene.file, "adapt", format!("theta = {}: must be in (0, 1]", opts.theta)));
    }
    if opts.reference == Some(0) {
        let msg = "--reference 0: generation 0 is the starting mesh, not finer than any level; give a generation \
                   above the finest level's (at least 1)";
        return Err(Error::scene(&scene.file, "adapt", msg.to_string()));
    }
    let start = Instant::now();
    let mut mesh = initial_mesh(scene)?;
    let mut root_area: Vec<f64> = (0..mesh.tris.len()).map(|t| mesh.area(t)).collect();
    let (mut rows, mut levels, mut stopped) = (Vec::<Row>::new(), Vec::<Kept>::new(), None);
    let mut reached = false;
    let mut last_root = root_area.clone();
    for level in 0.. {
        if opts.levels.is_some_and(|k| level >= k) {
            break;
        }
        if let Some(why) = refusal(scene, &mesh, opts, level, &rows, start) {
            stopped = Some(why);
            break;
        }
        let t0 = Instant::now();
        let min_angle = mesh.min_angle();
        let generations = reference::generations(&mesh, &root_area);
        let generation = generations.iter().copied().max().unwrap_or(0);
        let coarsest = generations.iter().copied().min().unwrap_or(0);
        if let Some(g) = opts.reference.filter(|&g| g <= coarsest) {
            return Err(not_finer(scene, g, level, coarsest));
        }
        let out = opts.out.as_ref().map(|d| files::level_results(d, level));
        if let (Some(dir), true) = (&opts.out, opts.gmsh) {
            export::write_gmsh(&mesh, &files::level_mesh(dir, level), opts.force)?;
        }
        let solved = solve(scene, mesh, out, opts.force, !opts.lean, opts.lean)?;
        let marked = dorfler(&solved.acc.eta2, opts.theta);
        let mut row = Row {
            level,
            triangles: solved.kept.mesh.tris.len(),
            unknowns: solved.unknowns,
            paper_dofs: solved.paper_dofs,
            contact_edges: contact_edges(scene, &solved.kept.mesh),
            estimator: solved.acc.global,
            terms: solved.acc.terms,
            worst_step: solved.acc.step,
            error: solved.error,
            min_angle,
            generation,
            marked: marked.iter().filter(|&&m| m).count(),
            time_estimator: solved.time.value(),
            time_dissipation: solved.time.dissipation.max(0.0).sqrt(),
            time_load: solved.time.load,
            ..Row::default()
        };
        let law = crate::fem::elasticity::Elasticity::new(&scene.material);
        if let (Some(pv), Some(last)) = (levels.last(), rows.last_mut()) {
            let inc = increments(&solved.kept, pv, &law, scene.rho, true)?;
            last.vs_next = Some(reference::max_distance(&inc));
            let parts: Vec<(f64, f64)> = inc.iter().map(|p| (p.gradient, p.fine_jumps)).collect();
            row.richardson = estimate::richardson(&parts, last.unknowns, row.unknowns);
        }
        let (raw, parent) = bisect(&solved.kept.mesh, &marked);
        let next_root = parent.iter().map(|&p| root_area[p]).collect();
        last_root = std::mem::replace(&mut root_area, next_root);
        mesh = Mesh::build(raw)?;
        row.wall = t0.elapsed().as_secs_f64();
        rows.push(row);
        let e = estimate::calibrated(&rows);
        let row = rows.last_mut().expect("pushed");
        row.estimate = e;
        report(row);
        reached = row.level >= estimate::TRUSTED_FROM && opts.target.zip(row.estimate).is_some_and(|(t, e)| e <= t);
        let done = reached || opts.until_unknowns.is_some_and(|n| row.unknowns >= n);
        if opts.reference.is_none() {
            levels.clear();
        }
        levels.push(solved.kept);
        if done {
            break;
        }
    }
    if let (Some(g), Some(finest)) = (opts.reference, levels.last()) {
        match reference_mesh(scene, finest, last_root, g, opts, &levels)? {
            Err(why) => stopped = Some(why),
            Ok(ref_mesh) => {
                let rf = solve(scene, ref_mesh, None, false, false, false)?;
                let law = crate::fem::elasticity::Elasticity::new(&scene.material);
                for (row, kept) in rows.iter_mut().zip(&levels) {
                    row.vs_reference = Some(distance(&rf.kept, kept, &law, scene.rho)?);
                }
            }
        }
    }
    if stopped.is_none() && opts.target.is_some() && !reached {
        stopped = Some(format!("the target was not reached in {} levels", rows.len()));
    }
    Ok(Outcome { rows, stopped })
}

/// The refusal of a reference of generation `g` that is not finer than level `level`, whose coarsest
/// triangles have generation `coarsest` ≥ g: the reference would be that level's own mesh (and every
/// later level's, refinement only raising generations).
fn not_finer(scene: &Scene, g: u32, level: usize, coarsest: u32) -> Error {
    let msg = format!(
        "--reference {g}: every triangle of level {level} already has generation {coarsest} or more, so a reference \
         of generation {g} is level {level}'s own mesh, not finer (its effectivity would be measured against \
         itself); give a generation above {coarsest} or fewer levels"
    );
    Error::scene(&scene.file, "adapt", msg)
}

/// The reference mesh of generation `g` over the finest level ([`overlay`]), or why its solve is not run
/// ([`reference_refusal`]): first for the triangles it has at least (one of generation k < g becomes
/// 2^(g−k)), so that a reference far beyond the machine is refused before it is built, then for its own.
fn reference_mesh(
    scene: &Scene,
    finest: &Kept,
    root_area: Vec<f64>,
    g: u32,
    opts: &Options,
    levels: &[Kept],
) -> Result<std::result::Result<Mesh, String>> {
    let gens = reference::generations(&finest.mesh, &root_area);
    let least = gens.iter().map(|&k| 1u64 << g.saturating_sub(k).min(63)).fold(0, u64::saturating_add);
    // each triangle has 3 edges and an edge at most 2 triangles
    if let Some(why) = reference_refusal(scene, (least, least.saturating_mul(3) / 2, 0), "at least ", opts, levels) {
        return Ok(Err(why));
    }
    let (mesh, _) = overlay(finest.mesh.clone(), root_area, g)?;
    let sizes = (mesh.tris.len() as u64, mesh.edges.len() as u64, contact_edges(scene, &mesh));
    Ok(reference_refusal(scene, sizes, "", opts, levels).map_or(Ok(mesh), Err))
}

/// Why the reference solve on a mesh of `sizes` (triangles, edges, contact edges; `least`: "at least "
/// when they are a lower bound) is not run: its memory,
/// beside the fields of every level kept for the comparison and its own (8 bytes a value, every time
/// node), does not fit.
fn reference_refusal(
    scene: &Scene,
    sizes: (u64, u64, u64),
    least: &str,
    opts: &Options,
    levels: &[Kept],
) -> Option<String> {
    let steps = scene.times.len() - 1;
    let mut estimate = Estimate::of_sizes(sizes, steps, false);
    let fields = |unknowns: u64| unknowns.saturating_mul(8).saturating_mul(steps as u64 + 1);
    let kept: u64 = levels.iter().map(|k| fields(k.space.n_dofs as u64)).sum();
    let more = kept.saturating_add(fields(estimate.unknowns));
    estimate.memory = estimate.memory.saturating_add(more);
    estimate.memory_metis = estimate.memory_metis.map(|m| m.saturating_add(more));
    let e = estimate.check(opts.max_memory, None, None).err()?;
    Some(format!("the reference solve ({least}{} unknowns) does not fit: {e}", estimate.unknowns))
}

/// Why level `level` on `mesh` is not run: its memory or results file does not fit, or the budget would
/// be exceeded (module doc); `None` if it may run.
fn refusal(scene: &Scene, mesh: &Mesh, opts: &Options, level: usize, rows: &[Row], start: Instant) -> Option<String> {
    let steps = scene.times.len() - 1;
    let sizes = (mesh.tris.len() as u64, mesh.edges.len() as u64, contact_edges(scene, mesh));
    let estimate = Estimate::of_sizes(sizes, steps, opts.out.is_some());
    if let Err(e) = estimate.check(opts.max_memory, opts.max_disk, opts.out.as_deref()) {
        return Some(format!("level {level} does not fit: {e}"));
    }
    let (b, last) = (opts.budget?, rows.last()?);
    let growth = 2.0 * mesh.edges.len() as f64 / last.unknowns.max(1) as f64;
    let predicted = start.elapsed().as_secs_f64() + last.wall * growth.max(1.0).powf(1.2);
    (predicted > b).then(|| {
        format!(
            "level {level} ({} unknowns) would end at about {predicted:.0} s, beyond the budget of {b:.0} s",
            2 * mesh.edges.len()
        )
    })
}

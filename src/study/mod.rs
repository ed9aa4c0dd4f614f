//! Convergence studies: one scene run at a list of levels (refinement, number of steps), with
//!
//! * true errors when the scene has an exact solution (max over time nodes and at the final time),
//! * the paper's consecutive-level error |||u_l − P u_{l−1}||| on level l (P: `fem::prolong`),
//! * the error against a finer reference run u_ref, the true error with u replaced by u_ref:
//!   |||u_ref − u_l|||² = Σ_{T ∈ reference mesh} ∫_T σ(u_ref − u_l):ε(u_ref − u_l) + Σ_{e ∈ E_l⁰} (2ρμ/h_e) ∫_e |[u_l]|²
//!   (u_l is linear on each reference triangle of nested meshes; the exact u has no jumps),
//!
//! all of them at the time nodes common to all levels — the nodes of the coarsest time grid — as the max
//! over these nodes and the value at the final time. Only there is u formed, so long runs stay cheap.
//! When the reference has the same mesh as a level (a time study against a semi-discrete reference), the
//! difference is measured in that mesh's discrete energy norm a_h(u_ref − u_l, u_ref − u_l)^{1/2}.
//! For the consecutive error |||·||| is the discrete energy norm a_h(·,·)^{1/2} of the finer level.

pub mod orders;

use crate::error::{Error, Result};
use crate::fem::norms::{ErrorEvaluator, ErrorNorms};
use crate::fem::prolong::{parent_triangles, prolong_with};
use crate::fem::space::Element;
use crate::scene::Scene;
use crate::sparse::energy;
use crate::stepping::{Problem, StepResult};
use std::time::Instant;

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
    pub wall: f64,
    pub iterations: usize,
    /// True errors, max over time nodes.
    pub max_err: Option<ErrorNorms>,
    /// True errors at the final time.
    pub final_err: Option<ErrorNorms>,
    /// max over the common nodes of the solution's discrete energy norm a_h(u, u)^{1/2}.
    pub norm_max: f64,
    /// Consecutive-level error: max over common nodes, and at the final time.
    pub consecutive: Option<[f64; 2]>,
    /// Error against the reference run: max over common nodes, and at the final time.
    pub reference: Option<[f64; 2]>,
}

/// A finished run kept for comparisons: problem and unknowns at the common time nodes.
struct Kept {
    problem: Problem,
    u: Vec<Vec<f64>>,
}

/// a_h(e, e)^{1/2} on the unknowns of `p`.
fn energy_norm(p: &Problem, e: &[f64]) -> f64 {
    energy(&p.stiffness, e).max(0.0).sqrt()
}

/// ‖u_fine − P u_coarse‖ at every common node: (max, final).
fn difference(fine: &Kept, coarse: &Kept) -> Result<[f64; 2]> {
    let mut worst: f64 = 0.0;
    let mut last = 0.0;
    let (c, f) = (&coarse.problem, &fine.problem);
    let parent = parent_triangles(&c.mesh, &f.mesh)?;
    for (uf, uc) in fine.u.iter().zip(&coarse.u) {
        let pu = prolong_with(&parent, (&c.mesh, &c.space), uc, (&f.mesh, &f.space));
        let d: Vec<f64> = uf.iter().zip(&pu).map(|(a, b)| a - b).collect();
        last = energy_norm(&fine.problem, &d);
        worst = worst.max(last);
    }
    Ok([worst, last])
}

/// |||u_ref − u_l||| at every common node (see module doc): (max, final).
fn reference_error(rf: &Kept, lv: &Kept) -> Result<[f64; 2]> {
    let (rp, lp) = (&rf.problem, &lv.problem);
    if rp.scene.mesh_level() == lp.scene.mesh_level() {
        let (mut worst, mut last): (f64, f64) = (0.0, 0.0);
        for (ur, ul) in rf.u.iter().zip(&lv.u) {
            let diff: Vec<f64> = ur.iter().zip(ul).map(|(a, b)| a - b).collect();
            last = energy_norm(lp, &diff);
            worst = worst.max(last);
        }
        return Ok([worst, last]);
    }
    let parent = parent_triangles(&lp.mesh, &rp.mesh)?;
    let jumps = ErrorEvaluator::new(&lp.mesh, &lp.space, &lp.law, lp.scene.rho);
    let (rel, lel): (Vec<Element>, Vec<Element>) = (
        (0..rp.mesh.tris.len()).map(|t| Element::new(&rp.mesh, t)).collect(),
        (0..lp.mesh.tris.len()).map(|t| Element::new(&lp.mesh, t)).collect(),
    );
    let (mut worst, mut last): (f64, f64) = (0.0, 0.0);
    for (ur, ul) in rf.u.iter().zip(&lv.u) {
        let (mr, ml) = (rp.space.midpoint_values(ur), lp.space.midpoint_values(ul));
        let mut en = jumps.jump_energy(&ml);
        for (t, el) in rel.iter().enumerate() {
            let gr = el.gradient(rp.mesh.tri_edges[t].map(|e| mr[e]));
            let pt = parent[t];
            let gl = lel[pt].gradient(lp.mesh.tri_edges[pt].map(|e| ml[e]));
            let d = [[gr[0][0] - gl[0][0], gr[0][1] - gl[0][1]], [gr[1][0] - gl[1][0], gr[1][1] - gl[1][1]]];
            en += el.area * lp.law.energy_density(d);
        }
        last = en.max(0.0).sqrt();
        worst = worst.max(last);
    }
    Ok([worst, last])
}

fn run_level(scene: &Scene, level: Level, common: &[f64], out: &mut LevelResult) -> Result<Kept> {
    let mut s = scene.clone();
    s.set_refine(level.refine)?;
    s.set_steps(level.steps)?;
    let start = Instant::now();
    let problem = Problem::new(s)?;
    let mut u = Vec::new();
    let (mut max_err, mut final_err, mut iterations, mut norm_max) = (None::<ErrorNorms>, None, 0, 0.0f64);
    let nodes: Vec<usize> = (0..problem.scene.times.len())
        .filter(|&n| common.iter().any(|&t| (t - problem.scene.times[n]).abs() <= 1e-12 * t.abs().max(1.0)))
        .collect();
    let first = problem.initial()?;
    let mut on_step = |r: &StepResult| -> Result<()> {
        iterations += r.iterations;
        if let Some(e) = r.errors {
            max_err = Some(max_err.map_or(e, |m: ErrorNorms| m.max(e)));
            final_err = Some(e);
        }
        if nodes.contains(&r.n) {
            norm_max = norm_max.max(r.energy.max(0.0).sqrt());
            u.push(r.u.clone());
        }
        Ok(())
    };
    on_step(&first)?;
    problem.run_selected(first, |n| nodes.contains(&n), on_step)?;
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
        k: problem.scene.times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max),
        dofs: problem.space.n_dofs,
        paper_dofs: problem.space.paper_dofs(),
        wall: start.elapsed().as_secs_f64(),
        iterations,
        max_err,
        final_err,
        norm_max,
        consecutive: None,
        reference: None,
    };
    Ok(Kept { problem, u })
}

/// Run the study. Levels must share the time nodes of the coarsest grid (e.g. steps doubling).
pub fn run_study(
    scene: &Scene,
    levels: &[Level],
    reference: Option<Level>,
    mut report: impl FnMut(&LevelResult),
) -> Result<Vec<LevelResult>> {
    if !scene.uniform_time {
        return Err(Error::scene(&scene.file, "time", "a study needs `T` and `steps` (uniform grids), not `times`"));
    }
    let n0 = levels.iter().map(|l| l.steps).min().ok_or_else(|| Error::scene(&scene.file, "study", "no levels"))?;
    let (t0, t1) = (scene.times[0], *scene.times.last().expect("nodes"));
    let common: Vec<f64> = (0..=n0).map(|i| t0 + (t1 - t0) * i as f64 / n0 as f64).collect();
    let reference = match reference {
        Some(l) => Some(run_level(scene, l, &common, &mut LevelResult::default())?),
        None => None,
    };
    let mut results = Vec::new();
    let mut prev: Option<Kept> = None;
    for &level in levels {
        let mut r = LevelResult::default();
        let kept = run_level(scene, level, &common, &mut r)?;
        if let Some(p) = &prev {
            r.consecutive = Some(difference(&kept, p)?);
        }
        if let Some(rf) = &reference {
            r.reference = Some(reference_error(rf, &kept)?);
        }
        report(&r);
        results.push(r);
        prev = Some(kept);
    }
    Ok(results)
}

/// CSV header matching [`csv_row`].
pub const CSV_HEADER: &str = "refine,steps,h,k,dofs,paper_dofs,wall_s,iterations,energy_max,h1_max,l2_max,energy_T,h1_T,l2_T,consecutive_max,consecutive_T,reference_max,reference_T,norm_max";

/// One CSV row (empty fields for quantities not computed).
pub fn csv_row(r: &LevelResult) -> String {
    let f = |v: Option<f64>| v.map(|x| format!("{x:.10e}")).unwrap_or_default();
    let m = |a: Option<ErrorNorms>, i: usize| f(a.map(|v| [v.energy, v.h1, v.l2][i]));
    let c = |a: Option<[f64; 2]>, i: usize| f(a.map(|v| v[i]));
    format!(
        "{},{},{:.10e},{:.10e},{},{},{:.6},{},{},{},{},{},{},{},{},{},{},{},{:.10e}",
        r.refine,
        r.steps,
        r.h,
        r.k,
        r.dofs,
        r.paper_dofs,
        r.wall,
        r.iterations,
        m(r.max_err, 0),
        m(r.max_err, 1),
        m(r.max_err, 2),
        m(r.final_err, 0),
        m(r.final_err, 1),
        m(r.final_err, 2),
        c(r.consecutive, 0),
        c(r.consecutive, 1),
        c(r.reference, 0),
        c(r.reference, 1),
        r.norm_max
    )
}

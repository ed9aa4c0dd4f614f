//! The planner's pilot runs and what their estimates say about one quantity.
//!
//! Two cheap sequences of the scene, both without its `[exact]` table (the planner must work without
//! one, and the cost of a run is measured without the error evaluation):
//! * **space**: the scene's mesh refined r₀, r₀+1, … at N/8 steps (`super::space_steps`): its estimates (Richardson
//!   on the distances between levels, [`crate::study::estimate`]) give the spatial error C_h hᵖ of the
//!   time-discrete problem, its wall times the cost model;
//! * **time**: one mesh (r₀+2) at N₀, 2N₀, … up to 2N steps (N₀: `super::time_base`, N the scene's), or
//!   N₀, 4N₀, 16N₀, 64N₀ when the doubling sequence is not in the asymptotic range (a slip that stops inside a step gives an O(k) error θk‖W‖ whose
//!   fraction θ of the step alternates under doubling, see `verification/cases/mms_stop.toml`): the time
//!   error C_k k^q of the space-discrete problem.

use super::model::{CostSample, TimeError};
use crate::error::{Error, Result};
use crate::scene::Scene;
use crate::study::estimate::level_errors;
use crate::study::richardson::{asymptotic, NormModel, Verdict, ORDER_TOL};
use crate::study::{estimate, Axis, Level, LevelResult, Sequence, SetupCache, Study};

/// The error the planner is asked to bound.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Quantity {
    /// The energy-norm error, max over the time nodes.
    Energy,
    /// A scalar output of `[quantities]` at T, by its study name (`max_slip`, `elastic_energy`, `traction_x_y`, …).
    Output(String),
}

impl Quantity {
    /// `energy-norm` (the energy-norm error; `energy` is its deprecated name), `elastic-energy` (the
    /// output ½a_h(u,u)) or an output name (`-` and `_` alike).
    pub fn parse(text: &str) -> Quantity {
        match text.replace('-', "_").as_str() {
            "energy_norm" | "energy" => Quantity::Energy,
            other => Quantity::Output(other.into()),
        }
    }

    /// The message for a deprecated name of a quantity, if `text` is one.
    pub fn deprecation(text: &str) -> Option<String> {
        (text == "energy").then(|| "--quantity energy is deprecated: write --quantity energy-norm".to_string())
    }

    pub fn describe(&self) -> String {
        match self {
            Quantity::Energy => "energy-norm error (max over the time nodes)".into(),
            Quantity::Output(name) => format!("error of the output {name} at T"),
        }
    }
}

/// What a sequence says about the quantity's error.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The axis the levels refine.
    pub size: Axis,
    /// Level sizes, coarse → fine.
    pub x: Vec<f64>,
    /// Estimated error per level (empty when refused).
    pub errors: Vec<f64>,
    pub verdicts: Vec<Verdict>,
    /// Observed order of the three finest levels.
    pub p: f64,
    /// Correlation exponent of the errors (energy norm only).
    pub beta: Option<f64>,
    /// Why there is no estimate.
    pub refused: Option<String>,
    /// Distance of each level to the one before (max over the common nodes; |ΔQ| for an output; 0 for
    /// the first level).
    pub distances: Vec<f64>,
    /// Why the estimates are bounds: the observed order exceeded the scene's order bound, which replaced it
    /// ([`fit`]).
    pub bounded: Option<String>,
    /// The finest level's error split into its smooth part and its singular part (order `p`, the scene's
    /// bound), with the smooth part's order: [smooth, singular, its order], where the observed order is
    /// above the bound and not falling ([`super::two_term`]).
    pub two_term: Option<[f64; 3]>,
    /// The order bound replaced the observed order only because the estimates are not yet consistent (the
    /// order not falling, and CR's optimal): a further level may make them so, and then the split applies
    /// (the space pilot grows by a level, as it does while not in the asymptotic range: `plan::space_pilot`).
    pub unsettled: bool,
}

impl Fit {
    /// Why the finest level cannot be trusted, if it cannot.
    pub fn not_in_range(&self) -> Option<String> {
        if let Some(why) = &self.refused {
            return Some(why.clone());
        }
        if self.bounded.is_some() {
            return None;
        }
        match self.verdicts.last() {
            Some(Verdict::InRange) => None,
            Some(Verdict::NotYet(why)) => Some(why.clone()),
            None => Some("no levels".into()),
        }
    }
}

/// The quantity's estimates in a finished study. `limit`: the energy-norm order a space sequence can
/// reach, min(1, α_min) from the scene's singular exponents (`fem::singular`); its levels are then judged
/// against it (the band of `study::richardson::asymptotic` around it, not around CR's 1), and an observed
/// order above it, still falling towards it, is replaced by it ([`bound_order`]).
pub fn fit(study: &Study, q: &Quantity, limit: Option<f64>) -> Result<Fit> {
    let (size, x) = estimate::sizes(&study.levels);
    match q {
        Quantity::Energy => {
            let e = &study.estimates;
            let distances = study
                .levels
                .iter()
                .map(|r| r.increment.as_ref().map_or(0.0, |v| v.iter().copied().fold(0.0, f64::max)))
                .collect();
            let mut f = Fit {
                size,
                x,
                errors: e.levels.iter().map(|l| l.error[0]).collect(),
                verdicts: e.levels.iter().map(|l| l.verdict.clone()).collect(),
                p: e.model.map_or(f64::NAN, |m| m.p),
                beta: e.model.map(|m| m.beta),
                refused: e.refused.clone(),
                distances,
                bounded: None,
                two_term: None,
                unsettled: false,
            };
            if let (Some(limit), Some(model), Axis::H) = (limit, e.model, size) {
                bound_order(&mut f, study, model, limit);
            }
            Ok(f)
        }
        Quantity::Output(name) => {
            let i = study.output_names.iter().position(|n| n == name).ok_or_else(|| {
                Error::scene(
                    "--quantity",
                    name,
                    format!("no such output; the scene has {}", study.output_names.join(", ")),
                )
            })?;
            let o = &study.outputs[i];
            let values: Vec<f64> = study.levels.iter().map(|r| r.outputs[i]).collect();
            let distances = std::iter::once(0.0).chain(values.windows(2).map(|w| (w[1] - w[0]).abs())).collect();
            let refused =
                o.model.is_none().then(|| format!("{name}: no monotone convergence of the three finest levels"));
            Ok(Fit {
                size,
                x,
                errors: if refused.is_some() { vec![] } else { o.levels.iter().map(|l| l.0).collect() },
                verdicts: o.levels.iter().map(|l| l.2.clone()).collect(),
                p: o.model.map_or(f64::NAN, |m| m.p),
                beta: None,
                refused,
                distances,
                bounded: None,
                two_term: None,
                unsettled: false,
            })
        }
    }
}

/// Judge a space sequence against the order bound `limit` = min(1, α_min). An observed order p at or below
/// it is judged in the band around `limit` (`study::richardson::asymptotic`). An order above it is
/// accepted but never extrapolated with: the model uses `limit` (a smooth part of the solution may dominate
/// the coarse levels; the singular part's order takes over as h → 0). Where the order is still falling —
/// the finest increment's order is more than `ORDER_TOL` below p — or the estimates are not consistent
/// with p (the GCI test around CR's order 1), the levels are also re-estimated with p = `limit` and β ≤ 1:
/// with Galerkin orthogonality (β = 1) the finest level's error is the sum of the increments still to
/// come, |e_L|² = Σ_{j>L} d_j², and increments decaying at least like h^limit give
/// |e_L| ≤ d_L/√(r^{2·limit} − 1), the estimate at p = `limit` (a smaller β only raises it). So the
/// prediction is a bound, not a hope. Where only the consistency is missing (the order not falling, and
/// CR's optimal) the fit is `unsettled`: the pilot grows, and with consistent estimates the split applies.
fn bound_order(f: &mut Fit, study: &Study, model: NormModel, limit: f64) {
    if model.p <= limit {
        f.verdicts = asymptotic(&f.x, model.p, &f.errors, limit);
        return;
    }
    let n = f.x.len();
    let finest = (n >= 3 && f.distances[n - 1] > 0.0)
        .then(|| (f.distances[n - 2] / f.distances[n - 1]).ln() / (f.x[n - 2] / f.x[n - 1]).ln());
    let falling = finest.is_some_and(|o| o < model.p - ORDER_TOL);
    let consistent = matches!(f.verdicts.last(), Some(Verdict::InRange));
    let optimal = model.p >= super::two_term::OPTIMAL_ORDER - super::two_term::ORDER_SCATTER;
    let split = (!falling && consistent && optimal)
        .then(|| {
            let orders = (limit, model.p.min(1.0), super::two_term::ORDER_SCATTER);
            super::two_term::split(&f.x, &f.distances, *f.errors.last().expect("levels"), orders)
        })
        .flatten();
    f.unsettled = !falling && !consistent && optimal;
    let how = if let Some([g, s]) = split {
        f.two_term = Some([g, s, model.p.min(1.0)]);
        format!(
            "the finest pilot level's error {:.3e} splits into a smooth part {g:.3e} (order {:.3}) and a singular part \
             {s:.3e} (order {limit:.3}) from the ratios of its last increments (`plan::two_term`)",
            g.hypot(s),
            model.p.min(1.0)
        )
    } else if falling || !consistent {
        let bounded = NormModel { p: limit, beta: model.beta.min(1.0), ..model };
        f.errors = level_errors(&study.levels, &bounded).iter().map(|e| e[0]).collect();
        format!(
            "{}: the finest pilot level is re-estimated with {limit:.3}",
            if falling { "still falling towards it" } else { "its estimates are not yet consistent" }
        )
    } else {
        "the finest pilot level's estimate stands".to_string()
    };
    f.bounded = Some(format!(
        "the observed space order {:.3} (finest increment {}) is above min(1, α_min) = {limit:.3}, the order the \
         scene's corners allow (`tresca-cr check`); {how}, and the error is extrapolated with {limit:.3}{}",
        model.p,
        finest.map_or("-".into(), |o| format!("{o:.3}")),
        if split.is_some() { " for that part" } else { " (a bound)" }
    ));
    f.p = limit;
}

/// The scene the pilots run: without `[exact]`, with the quantity among its outputs.
pub fn pilot_scene(scene: &Scene, q: &Quantity) -> Result<Scene> {
    if !scene.uniform_time {
        return Err(Error::scene(
            &scene.file,
            "time",
            "the planner needs `T` and `steps` (uniform grids), not `times`",
        ));
    }
    let mut s = scene.clone();
    s.exact = None;
    if let Quantity::Output(name) = q {
        let on_normal = ["contact_length", "max_pressure"].contains(&name.as_str());
        if on_normal && !scene.has_normal_unknowns() {
            return Err(Error::scene(
                &scene.file,
                "--quantity",
                format!("`{name}` is measured on the contact pressure, and this scene has no unilateral or Coulomb contact part"),
            ));
        }
        let on_contact = ["max_slip", "stick_length"].contains(&name.as_str()) || name.starts_with("traction_");
        if on_contact && !scene.has_contact() {
            return Err(Error::scene(
                &scene.file,
                "--quantity",
                format!("`{name}` is measured on the contact part, and this scene has none (no boundary part of kind contact)"),
            ));
        }
        let mut o = crate::study::outputs::selected(&s);
        match name.as_str() {
            "max_slip" => o.max_slip = true,
            "stick_length" => o.stick_length = true,
            "contact_length" => o.contact_length = true,
            "max_pressure" => o.max_pressure = true,
            "elastic_energy" => o.elastic_energy = true,
            _ => {}
        }
        if !crate::study::outputs::names(&o).contains(name) {
            return Err(Error::scene(
                &scene.file,
                "--quantity",
                format!("`{name}` is not an output of this scene (energy-norm, elastic-energy, max-slip, stick-length, contact-length, max-pressure, or a traction_x_y of [quantities])"),
            ));
        }
        s.outputs = Some(o);
    }
    Ok(s)
}

/// A sequence that adds levels only while their predicted cost fits what is left of the pilot budget.
pub struct Runner<'a> {
    seq: Sequence<'a>,
    pub spent: f64,
}

impl<'a> Runner<'a> {
    /// A pilot sequence whose levels take their set-ups from `cache` (one per mesh for all the pilots of
    /// a plan: the time pilot's levels share one mesh, and the space pilot returns to it), and the levels
    /// an earlier pilot ran with the same common nodes ([`Sequence::sharing_runs`]).
    pub fn new(scene: &'a Scene, min_steps: usize, cache: &SetupCache) -> Result<Runner<'a>> {
        let seq =
            Sequence::with_cache(scene, min_steps, None, None, cache.clone())?.without_consecutive().sharing_runs();
        Ok(Runner { seq, spent: 0.0 })
    }

    /// Run `level`, unless `predicted` seconds would take the pilot past `budget` or the level would not
    /// fit in the available memory together with the two levels a sequence keeps: then the reason is
    /// returned and nothing is run.
    pub fn push(&mut self, level: Level, predicted: f64, budget: f64) -> Result<Option<String>> {
        if !self.seq.levels().is_empty() && self.spent + predicted > budget {
            return Ok(Some(format!(
                "the pilot budget ({budget:.3} s left) does not allow level {}:{} (predicted {predicted:.3} s): raise \
                 --pilot-budget for more evidence",
                level.refine, level.steps
            )));
        }
        let mut s = self.seq.scene().clone();
        s.set_refine(level.refine)?;
        let need = crate::scene::budget::Estimate::of(&s, level.steps, false)?.memory.saturating_mul(3) / 2;
        if let Some(m) = crate::scene::budget::available_memory().filter(|&m| need > m) {
            return Ok(Some(format!(
                "pilot level {}:{} would need ~{} with the two levels kept, {} are available",
                level.refine,
                level.steps,
                crate::error::human(need),
                crate::error::human(m)
            )));
        }
        let r = self.seq.push(level)?;
        // a level an earlier pilot ran is not run again: it costs nothing more
        self.spent += if r.shared_run { 0.0 } else { r.wall };
        Ok(None)
    }

    pub fn levels(&self) -> &[LevelResult] {
        self.seq.levels()
    }

    pub fn study(&self) -> Study {
        self.seq.finish()
    }
}

impl Fit {
    /// The bound on the time error for every grid of at least `min_steps` steps, from the levels of a
    /// time sequence (steps `steps`, ratio `ratio`) with at least that many ([`TimeError::bound`]).
    pub fn time_bound(&self, steps: &[usize], min_steps: usize, ratio: usize) -> TimeError {
        let from = steps.iter().position(|&n| n >= min_steps).unwrap_or(steps.len());
        let sum: f64 = self.distances.iter().skip(from + 1).sum();
        TimeError::bound(sum, ratio as f64, steps.len() - from)
    }
}

/// The time pilot on mesh level `refine`: grids doubling from `first` steps up to twice the scene's
/// The time pilot's mesh and grids: the refinement, the first number of steps N and the steps of the
/// runs whose time error is to be bounded.
pub struct TimeGrids {
    pub refine: u32,
    pub first: usize,
    pub steps: usize,
}

/// `steps` (at least four), then N, 4N, 16N, 64N from `first` if the doubling sequence is not in the
/// asymptotic range (module doc) and its distances do not already bound the time error of grids of
/// `steps` steps or more by `enough` ([`Fit::time_bound`]); then the run's cost of a step on its mesh
/// ([`super::step_cost`]). The levels' set-ups come from `cache`. (On a coarser mesh the time grids move the solution more — a stick–slip front crosses
/// fewer, larger edges — so the bound would be looser and the space pilot could not sample time coarsely.)
pub fn time_pilot(
    scene: &Scene,
    grids: TimeGrids,
    q: &Quantity,
    enough: f64,
    budget: f64,
    cache: &SetupCache,
) -> Result<TimePilot> {
    let TimeGrids { refine, first, steps } = grids;
    let mut spent = 0.0;
    let mut last = None;
    for ratio in [2usize, 4] {
        let mut grids = vec![first];
        while grids.len() < 4 || (ratio == 2 && *grids.last().expect("grids") < 2 * steps) {
            let next = grids.last().expect("grids").checked_mul(ratio);
            grids.push(next.ok_or_else(|| Error::scene(&scene.file, "steps", "too many steps"))?);
        }
        let mut run = Runner::new(scene, first, cache)?;
        for &n in &grids {
            // a step costs about the same at every N: the next level costs ratio × the last one's steps
            let predicted = run.levels().last().map_or(0.0, |r| (r.wall - r.setup) * ratio as f64 + r.setup);
            if let Some(why) = run.push(Level { refine, steps: n }, predicted, budget - spent)? {
                if run.levels().is_empty() {
                    return Err(Error::scene(&scene.file, "plan", format!("no time pilot: {why}")));
                }
                break;
            }
        }
        spent += run.spent;
        let study = run.study();
        let f = fit(&study, q, None)?;
        let run_steps: Vec<usize> = study.levels.iter().map(|l| l.steps).collect();
        let done = f.not_in_range().is_none() || f.time_bound(&run_steps, steps, ratio).at(0.0) <= enough;
        last = Some((study, ratio));
        if done {
            break;
        }
    }
    let (study, ratio) = last.expect("two ratios tried");
    let longest = study.levels.iter().max_by_key(|l| l.steps).expect("the time pilot ran a level");
    let own = (longest.wall - longest.setup).max(0.0);
    let (mut step_costs, timed) = super::step_cost::run_steps(scene, longest, own, budget - spent, cache)?;
    if step_costs.is_empty() {
        // no timed run fits in the pilot budget: the longest level's own steps (`super::step_cost` doc)
        let n = longest.dofs as f64;
        step_costs.push((CostSample { n, setup: 0.0, step: own / longest.steps as f64 }, longest.steps));
    }
    Ok(TimePilot { study, ratio, spent: spent + timed, step_costs })
}

/// What the time pilot gives: its study, the ratio of its grids, the seconds it took (the timed runs
/// included) and the run's per-step cost samples on its mesh ([`super::step_cost::run_steps`]).
pub struct TimePilot {
    pub study: Study,
    pub ratio: usize,
    pub spent: f64,
    pub step_costs: Vec<(CostSample, usize)>,
}

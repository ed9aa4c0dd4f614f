//! The `adapt` part of the summary (fields in the parent module's doc).

use serde::{Deserialize, Serialize};
use tresca_cr::adapt::estimator::TERMS;
use tresca_cr::adapt::{Options, Row};

/// One level of the adaptive loop.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct AdaptLevel {
    pub level: usize,
    pub triangles: usize,
    pub unknowns: usize,
    pub paper_dofs: usize,
    pub generation: u32,
    pub estimator: f64,
    pub error: Option<f64>,
    pub error_kind: Option<String>,
    pub effectivity: Option<f64>,
    pub vs_next: Option<f64>,
    pub vs_reference: Option<f64>,
    pub min_angle: f64,
    pub marked: usize,
    pub wall: f64,
    pub worst_step: usize,
    /// The terms of η at its worst node, by name (`estimator::TERMS`), not squared.
    pub terms: std::collections::BTreeMap<String, f64>,
    /// The time indicator η_k = D^{1/2} + 3L and its parts (`adapt::time`).
    pub time_estimator: f64,
    pub time_dissipation: f64,
    pub time_load: f64,
    /// The error estimate (η calibrated along the sequence, `adapt::estimate`) and the Richardson
    /// estimate R it is calibrated against; from level 1 on.
    #[serde(default)]
    pub estimate: Option<f64>,
    #[serde(default)]
    pub richardson: Option<f64>,
}

impl AdaptLevel {
    /// The level of `r`; `exact`: the scene has `[exact]` (its errors are true ones).
    pub fn of(r: &Row, exact: bool) -> AdaptLevel {
        let error = r.error_or_estimate();
        AdaptLevel {
            level: r.level,
            triangles: r.triangles,
            unknowns: r.unknowns,
            paper_dofs: r.paper_dofs,
            generation: r.generation,
            estimator: r.estimator,
            error,
            error_kind: r.error_kind(exact).map(String::from),
            effectivity: error.map(|e| r.estimator / e),
            vs_next: r.vs_next,
            vs_reference: r.vs_reference,
            min_angle: r.min_angle,
            marked: r.marked,
            wall: r.wall,
            worst_step: r.worst_step,
            terms: TERMS.iter().zip(r.terms).map(|(n, v)| (n.to_string(), v.max(0.0).sqrt())).collect(),
            time_estimator: r.time_estimator,
            time_dissipation: r.time_dissipation,
            time_load: r.time_load,
            estimate: r.estimate,
            richardson: r.richardson,
        }
    }
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct AdaptSummary {
    pub theta: f64,
    pub levels_asked: Option<usize>,
    pub target: Option<f64>,
    pub reference_generation: Option<u32>,
    pub exact: bool,
    pub levels: Vec<AdaptLevel>,
    pub stopped: Option<String>,
}

impl AdaptSummary {
    pub fn of(o: &Options, exact: bool, rows: &[Row], stopped: Option<String>) -> AdaptSummary {
        AdaptSummary {
            theta: o.theta,
            levels_asked: o.levels,
            target: o.target,
            reference_generation: o.reference,
            exact,
            levels: rows.iter().map(|r| AdaptLevel::of(r, exact)).collect(),
            stopped,
        }
    }
}

/// `plan`'s weighing of the adaptive route against the uniform one (`plan::adaptive`).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct AdaptiveRoute {
    /// `uniform`, `adaptive` or `neither`; `null` when the routes were not weighed (`refused` says why).
    pub choice: Option<String>,
    pub reason: Option<String>,
    pub refused: Option<String>,
    /// The indicator η predicted where the route's estimate reaches `estimate_target`.
    pub eta: Option<f64>,
    /// The error estimate the route must reach (`plan::adaptive::ESTIMATE_SHARE` of the target) and the
    /// pilot's calibration E/η (`adapt::estimate`).
    #[serde(default)]
    pub estimate_target: Option<f64>,
    #[serde(default)]
    pub calibration: Option<f64>,
    /// The laws' orders r in η = c N^(−r) (the uniform pilot is no longer run: `null`).
    pub adaptive_rate: Option<f64>,
    pub uniform_rate: Option<f64>,
    pub uniform_unknowns: Option<f64>,
    pub uniform_wall: Option<f64>,
    pub uniform_memory: Option<u64>,
    pub adaptive_unknowns: Option<f64>,
    pub adaptive_levels: Option<usize>,
    pub adaptive_wall: Option<f64>,
    pub adaptive_memory: Option<u64>,
    pub pilot_wall: Option<f64>,
    /// The time steps the pilots ran (the space pilot's), and the route's (the plan's).
    pub pilot_steps: Option<usize>,
    pub steps: Option<usize>,
    pub adaptive_pilot: Vec<AdaptLevel>,
    pub uniform_pilot: Vec<AdaptLevel>,
    /// With `--run` where the route was recommended: the levels of its `adapt` loop.
    #[serde(default)]
    pub run: Vec<AdaptLevel>,
}

impl AdaptiveRoute {
    /// The weighing `w`, or why there is none; `exact`: the scene has `[exact]`.
    pub fn of(w: &std::result::Result<tresca_cr::plan::adaptive::AdaptivePlan, String>, exact: bool) -> AdaptiveRoute {
        let none = AdaptiveRoute {
            choice: None,
            reason: None,
            refused: None,
            eta: None,
            estimate_target: None,
            calibration: None,
            adaptive_rate: None,
            uniform_rate: None,
            uniform_unknowns: None,
            uniform_wall: None,
            uniform_memory: None,
            adaptive_unknowns: None,
            adaptive_levels: None,
            adaptive_wall: None,
            adaptive_memory: None,
            pilot_wall: None,
            pilot_steps: None,
            steps: None,
            adaptive_pilot: vec![],
            uniform_pilot: vec![],
            run: vec![],
        };
        let w = match w {
            Ok(w) => w,
            Err(why) => return AdaptiveRoute { refused: Some(why.clone()), ..none },
        };
        let rows = |rs: &[Row]| rs.iter().map(|r| AdaptLevel::of(r, exact)).collect();
        AdaptiveRoute {
            choice: Some(w.choice.name().into()),
            reason: Some(w.reason.clone()),
            eta: Some(w.eta),
            estimate_target: Some(w.estimate_target),
            calibration: Some(w.calibration),
            adaptive_rate: Some(-w.adaptive_law.p),
            uniform_unknowns: Some(w.uniform_unknowns),
            uniform_wall: Some(w.uniform_wall),
            uniform_memory: Some(w.uniform_memory),
            adaptive_unknowns: Some(w.unknowns),
            adaptive_levels: Some(w.levels),
            adaptive_wall: Some(w.wall),
            adaptive_memory: Some(w.memory),
            pilot_wall: Some(w.pilot_wall),
            pilot_steps: Some(w.pilot_steps),
            steps: Some(w.steps),
            adaptive_pilot: rows(&w.adaptive_pilot),
            ..none
        }
    }
}

//! The `plan` part of the summary (fields in the parent module's doc).

use super::Level;
use serde::{Deserialize, Serialize};
use tresca_cr::plan::model::{Combine, TimeError};
use tresca_cr::plan::Plan;

/// One pilot sequence and what it says about the error.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Pilot {
    pub size: String,
    pub levels: Vec<Level>,
    pub x: Vec<f64>,
    pub errors: Vec<f64>,
    pub verdicts: Vec<String>,
    pub p: f64,
    pub beta: Option<f64>,
    pub refused: Option<String>,
}

impl Pilot {
    fn of(study: &tresca_cr::study::Study, fit: &tresca_cr::plan::pilot::Fit) -> Pilot {
        Pilot {
            size: fit.size.to_string(),
            levels: study.levels.iter().map(|r| Level::of(r, None)).collect(),
            x: fit.x.clone(),
            errors: fit.errors.clone(),
            verdicts: fit.verdicts.iter().map(|v| v.text()).collect(),
            p: fit.p,
            beta: fit.beta,
            refused: fit.refused.clone(),
        }
    }
}

/// e_h = space_c h^space_p (⊕ singular_c h^singular_p, a two-term spatial error: `plan::two_term`);
/// e_k = time_c k^time_p or ≤ time_bound; combined as `combine`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ErrorModel {
    pub space_c: f64,
    pub space_p: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub singular_c: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub singular_p: Option<f64>,
    pub time_c: Option<f64>,
    pub time_p: Option<f64>,
    pub time_bound: Option<f64>,
    pub combine: String,
}

/// wall = setup_c n^setup_p + N · step · n ln n.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct CostModel {
    pub setup_c: f64,
    pub setup_p: f64,
    pub step: f64,
}

#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    pub refine: u32,
    pub steps: usize,
    pub unknowns: u64,
    pub h: f64,
    pub k: f64,
    pub error: f64,
    pub space_error: f64,
    pub time_error: f64,
    pub wall: f64,
    pub memory: u64,
}

impl From<&tresca_cr::plan::Candidate> for Candidate {
    fn from(c: &tresca_cr::plan::Candidate) -> Candidate {
        Candidate {
            refine: c.refine,
            steps: c.steps,
            unknowns: c.unknowns,
            h: c.h,
            k: c.k,
            error: c.error,
            space_error: c.space_error,
            time_error: c.time_error,
            wall: c.wall,
            memory: c.memory,
        }
    }
}

/// What running the plan (`--run`) achieved.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Achieved {
    pub estimate: f64,
    pub space: f64,
    pub time: f64,
    pub true_error: Option<f64>,
    pub met: bool,
    pub levels: Vec<Level>,
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct PlanSummary {
    pub target: f64,
    pub quantity: String,
    pub budget: f64,
    pub pilot_budget: f64,
    pub pilot_wall: f64,
    pub space_pilot: Pilot,
    pub time_pilot: Pilot,
    pub time_ratio: usize,
    pub scene_steps: usize,
    pub error_model: Option<ErrorModel>,
    pub cost_model: Option<CostModel>,
    pub plan: Option<Candidate>,
    pub runners_up: Vec<Candidate>,
    pub over_budget: Option<Candidate>,
    pub solver: String,
    pub tol: f64,
    pub notes: Vec<String>,
    pub refused: Option<String>,
    pub achieved: Option<Achieved>,
    /// The adaptive route weighed against this plan (absent in summaries written before it existed).
    #[serde(default)]
    pub adaptive: Option<super::AdaptiveRoute>,
}

impl PlanSummary {
    pub fn of(p: &Plan, quantity: &str, achieved: Option<Achieved>) -> PlanSummary {
        let error_model = p.error.map(|m| {
            let (time_c, time_p, time_bound) = match m.time {
                TimeError::Law(t) => (Some(t.c), Some(t.p), None),
                TimeError::Bound(b) => (None, None, Some(b)),
            };
            let combine = match m.combine {
                Combine::Quadrature => "quadrature",
                Combine::Sum => "sum",
            };
            ErrorModel {
                space_c: m.space.c,
                space_p: m.space.p,
                singular_c: m.singular.map(|s| s.c),
                singular_p: m.singular.map(|s| s.p),
                time_c,
                time_p,
                time_bound,
                combine: combine.into(),
            }
        });
        PlanSummary {
            target: p.options.target,
            quantity: quantity.into(),
            budget: p.options.budget,
            pilot_budget: p.options.pilot_budget,
            pilot_wall: p.pilot_wall,
            space_pilot: Pilot::of(&p.space, &p.space_fit),
            time_pilot: Pilot::of(&p.time, &p.time_fit),
            time_ratio: p.time_ratio,
            scene_steps: p.scene_steps,
            error_model,
            cost_model: p.cost.map(|c| CostModel { setup_c: c.setup.c, setup_p: c.setup.p, step: c.step }),
            plan: p.best.first().map(Candidate::from),
            runners_up: p.best.iter().skip(1).map(Candidate::from).collect(),
            over_budget: p.over_budget.as_ref().map(Candidate::from),
            solver: p.solver.to_string(),
            tol: p.tol,
            notes: p.notes.clone(),
            refused: p.refused.clone(),
            achieved,
            adaptive: None,
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// A plan summary with every part filled, for the round trip of the parent module.
    pub fn plan(level: Level) -> PlanSummary {
        let pilot = Pilot {
            size: "h".into(),
            levels: vec![level.clone()],
            x: vec![0.5, 0.25],
            errors: vec![1e-2, 5e-3],
            verdicts: vec!["in the asymptotic range".into()],
            p: 1.0,
            beta: Some(0.7),
            refused: None,
        };
        let c = Candidate {
            refine: 3,
            steps: 64,
            unknowns: 10_000,
            h: 0.1,
            k: 1.0 / 64.0,
            error: 1e-3,
            space_error: 9e-4,
            time_error: 1e-4,
            wall: 0.5,
            memory: 1 << 25,
        };
        PlanSummary {
            target: 1e-3,
            quantity: "energy".into(),
            budget: 3600.0,
            pilot_budget: 360.0,
            pilot_wall: 0.2,
            space_pilot: pilot.clone(),
            time_pilot: Pilot { size: "k".into(), beta: None, ..pilot },
            time_ratio: 2,
            scene_steps: 16,
            error_model: Some(ErrorModel {
                space_c: 0.1,
                space_p: 1.0,
                singular_c: Some(0.02),
                singular_p: Some(0.7112),
                time_c: None,
                time_p: None,
                time_bound: Some(1e-5),
                combine: "quadrature".into(),
            }),
            cost_model: Some(CostModel { setup_c: 1e-6, setup_p: 1.2, step: 1e-8 }),
            plan: Some(c),
            runners_up: vec![Candidate { refine: 4, ..c }],
            over_budget: None,
            solver: "ssn".into(),
            tol: 1e-10,
            notes: vec!["a note".into()],
            refused: None,
            achieved: Some(Achieved {
                estimate: 9e-4,
                space: 8e-4,
                time: 1e-4,
                true_error: Some(9.5e-4),
                met: true,
                levels: vec![level],
            }),
            adaptive: Some(super::super::AdaptiveRoute::of(&Err("not weighed".into()), false)),
        }
    }
}

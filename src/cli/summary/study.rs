//! The `study` part of the summary, and the study level that `plan`'s pilots reuse (fields in the parent
//! module's doc).

use super::Errors;
use serde::{Deserialize, Serialize};
use tresca_cr::study::LevelResult;

/// A level's estimate.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct LevelEstimate {
    pub error_max: f64,
    pub error_t: f64,
    pub gci: f64,
    pub verdict: String,
}

/// One level of a study or of a planner's pilot.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Level {
    pub refine: u32,
    pub steps: usize,
    pub h: f64,
    pub k: f64,
    pub dofs: usize,
    pub paper_dofs: usize,
    pub wall: f64,
    pub setup: f64,
    pub iterations: usize,
    pub max_err: Option<Errors>,
    pub common_err: Option<Errors>,
    pub final_err: Option<Errors>,
    pub norm_max: f64,
    pub consecutive: Option<[f64; 2]>,
    pub reference: Option<[f64; 2]>,
    pub estimate: Option<LevelEstimate>,
    pub outputs: Vec<f64>,
}

impl Level {
    pub fn of(r: &LevelResult, estimate: Option<LevelEstimate>) -> Level {
        Level {
            refine: r.refine,
            steps: r.steps,
            h: r.h,
            k: r.k,
            dofs: r.dofs,
            paper_dofs: r.paper_dofs,
            wall: r.wall,
            setup: r.setup,
            iterations: r.iterations,
            max_err: r.max_err.map(Errors::from),
            common_err: r.common_err.map(Errors::from),
            final_err: r.final_err.map(Errors::from),
            norm_max: r.norm_max,
            consecutive: r.consecutive,
            reference: r.reference,
            estimate,
            outputs: r.outputs.clone(),
        }
    }
}

/// The energy-norm model of a study.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Estimates {
    pub size: String,
    pub p: Option<f64>,
    pub beta: Option<f64>,
    pub refused: Option<String>,
}

/// A scalar output's estimate at one level.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct OutputLevel {
    pub estimate: f64,
    pub gci: f64,
    pub verdict: String,
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct OutputEstimate {
    pub name: String,
    pub p: Option<f64>,
    pub limit: Option<f64>,
    pub levels: Vec<OutputLevel>,
}

/// The level spelled refine:steps.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct LevelSpec {
    pub refine: u32,
    pub steps: usize,
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct StudySummary {
    pub levels: Vec<Level>,
    pub reference: Option<LevelSpec>,
    pub estimates: Estimates,
    pub output_names: Vec<String>,
    pub outputs: Vec<OutputEstimate>,
    pub difference_files: Vec<String>,
}

impl StudySummary {
    pub fn of(s: &tresca_cr::study::Study, reference: Option<tresca_cr::study::Level>) -> StudySummary {
        let e = &s.estimates;
        let levels = s
            .levels
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let est = e.levels.get(i).map(|l| LevelEstimate {
                    error_max: l.error[0],
                    error_t: l.error[1],
                    gci: l.gci,
                    verdict: l.verdict.text(),
                });
                Level::of(r, est)
            })
            .collect();
        let outputs = s
            .outputs
            .iter()
            .map(|o| OutputEstimate {
                name: o.name.clone(),
                p: o.model.map(|m| m.p),
                limit: o.model.map(|m| m.limit),
                levels: o
                    .levels
                    .iter()
                    .map(|(est, gci, v)| OutputLevel { estimate: *est, gci: *gci, verdict: v.text() })
                    .collect(),
            })
            .collect();
        StudySummary {
            levels,
            reference: reference.map(|l| LevelSpec { refine: l.refine, steps: l.steps }),
            estimates: Estimates {
                size: e.size.to_string(),
                p: e.model.map(|m| m.p),
                beta: e.model.map(|m| m.beta),
                refused: e.refused.clone(),
            },
            output_names: s.output_names.clone(),
            outputs,
            difference_files: s.difference_files.iter().map(|f| f.display().to_string()).collect(),
        }
    }
}

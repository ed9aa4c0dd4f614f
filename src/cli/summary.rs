//! `--json FILE`: the machine-readable summary of `check`, `run`, `study`, `plan` and `adapt`, written (atomically:
//! a temporary file renamed) when the subcommand ends, also when a run stops on a solver failure. The
//! verification scripts read it instead of the human messages, which may be reworded at any time. Its
//! structs mirror library types (`LevelResult`, `plan::Candidate`, …) on purpose: the schema is a contract
//! with the scripts and stays put when the library renames or regroups its fields.
//!
//! Schema (version [`SCHEMA`]; times in seconds, sizes in unknowns or bytes; a non-finite number is
//! written as `null`):
//!
//! | field | meaning |
//! |---|---|
//! | `schema` | the schema version, [`SCHEMA`] |
//! | `command` | `check`, `run`, `study`, `plan` or `adapt` |
//! | `version`, `commit` | the crate version and the git commit of the build (`-dirty` when it had changes) |
//! | `scene` | the scene file as given |
//! | `status` | `completed`, `stopped: <why>` (a run's solver failure) or `refused: <why>` (a plan's refusal, an adaptive loop stopped before its goal) |
//! | `wall` | wall time of the whole subcommand |
//! | `check`, `run`, `study`, `plan`, `adapt` | the part of the subcommand that ran (the others `null`) |
//!
//! `check` ([`CheckSummary`]): `vertices`, `triangles`, `edges`, `h` (largest edge) of the mesh; `unknowns`,
//! `paper_dofs` (the paper's count 2(edges − Dirichlet edges)), `contact_unknowns` — all of the asked level,
//! also where it is counted from a coarser level set up (above `check`'s cap, `src/cli/check.rs`), as `run`
//! would report them; `steps`; `solver`, `tol`,
//! `max_iter`; `exact` (true errors computed); `setup` ([`Phases`], of the level set up); `memory`, `disk`: the pre-run estimate
//! of the peak memory and of the results file (bytes); `singular` ([`Singular`]): every polygon corner and
//! change of condition with its leading exponent α and `floor` (α ≤ `fem::singular::FLOOR_EXPONENT`: an error
//! floor, not a rate), `uniform_order` = min(1, min Re α), `adaptive_order` ½.
//!
//! `run` ([`RunSummary`]): `refine` (the mesh level), `unknowns`, `paper_dofs`, `contact_edges`, `steps` (time
//! steps of the run); `solver`, `tol`; `setup` ([`Phases`]); `ordering` (how K's fill-reducing ordering
//! was made: AMD, nested dissection by coordinates, or METIS when the factor by coordinates would not fit
//! in memory; absent from the summaries of older versions); `step_stats`: one [`Step`] per step solved (step
//! 0 included: `n`, `t`, `iterations`, `residual` (the solver's final KKT residual), `stick`, `slip` (contact
//! edges), `errors` (true errors at tⁿ with `[exact]`, else `null`), and with a unilateral or Coulomb part
//! `lengths`: `contact_length`, `separated_length`, `stick_length` of Γ_C); `iterations` (sum over the steps),
//! `max_residual`; `max_errors`: the true errors, max over the time nodes (`null` without `[exact]`);
//! `output`: the results file (`null` when none was written).
//!
//! [`Phases`]: the set-up's wall times `space` (mesh binding and numbering of V_h), `assembly` (K and the
//! loads, with the fill-reducing ordering beside them), `factorisation` (Cholesky of K), `superposition`
//! (the load responses K⁻¹b_j) and `condensation` (C = EᵀK⁻¹E and W = L_cc⁻¹).
//!
//! [`Errors`]: `energy` (the a_h norm with the jump term), `h1` (broken H¹ seminorm) and `l2`.
//!
//! `study` ([`StudySummary`]): `levels`, one [`Level`] per level, coarse to fine: `refine`, `steps`, `h`, `k`,
//! `dofs`, `paper_dofs`, `wall`, `setup` (its set-up wall time), `iterations`; the true errors `max_err` (max
//! over its own nodes), `common_err` (max over the nodes common to all levels), `final_err` (at T); `norm_max`
//! (max over the common nodes of |||u|||); `consecutive` and `reference`: [max over common nodes, at T] of
//! |||u_l − P u_{l−1}||| and of the error against the `--reference` run; `estimate`: [`study::LevelEstimate`]
//! (`error_max`, `error_t`, `gci`, `verdict`) or `null`; `outputs`: the scalar outputs at T, in the order of
//! `output_names`. `reference`: the reference level (`refine`, `steps`) or `null`. `estimates`
//! ([`study::Estimates`]): `size` (`h` or `k`), `p`, `beta` (the model of the three finest levels, `null` when
//! refused), `refused` (why no estimate). `outputs`: per scalar output `name`, `p`, `limit` (the extrapolated
//! value, `null` without a model) and per level `estimate`, `gci`, `verdict`. `difference_files`: the files
//! `--differences` wrote.
//!
//! `plan` ([`PlanSummary`]): `target`, `quantity`, `budget`, `pilot_budget`; `pilot_wall` (the pilots' wall
//! time); `space_pilot`, `time_pilot` ([`Pilot`]: `size`, `levels` ([`Level`] without true errors: the
//! pilots run the scene without `[exact]`), `x`, `errors`, `verdicts`, `p`, `beta`, `refused`); `time_ratio`,
//! `scene_steps`; `error_model` (`space_c`, `space_p`; `time_c`, `time_p` for a power law or `time_bound`;
//! `combine`: `quadrature` or `sum`); `cost_model` (`setup_c`, `setup_p`, `step`: wall = setup_c n^setup_p
//! plus N · step · n ln n); `plan` and `runners_up` ([`Candidate`]: `refine`, `steps`, `unknowns`, `h`, `k`,
//! `error`, `space_error`, `time_error`, `wall`, `memory`), `over_budget`; `solver`, `tol`; `notes`;
//! `refused`; `achieved` (with `--run`, [`Achieved`]: `estimate`, `space`, `time`, `true_error`, `met`,
//! `levels`); `adaptive` ([`AdaptiveRoute`], energy-norm targets only; absent in older summaries): the
//! adaptive route weighed against the uniform plan (`src/plan/adaptive.rs`): `choice` (`uniform`,
//! `adaptive`, `neither`), `reason`, `refused` (why not weighed), `estimate_target` (the error estimate
//! the route must reach), `calibration` (E/η of the pilot's last level), `eta` (the indicator predicted
//! there), `adaptive_rate` (r in η = c N^(−r)), `uniform_rate` (`null`: no uniform pilot), `uniform_unknowns`,
//! `uniform_wall`, `uniform_memory`, `adaptive_unknowns`, `adaptive_levels`, `adaptive_wall` (the whole
//! sequence), `adaptive_memory` (its last level), `pilot_wall`, `adaptive_pilot` (its levels, as `adapt`'s),
//! `uniform_pilot` (empty), `run` (with `--run` where the route was recommended: the levels of its `adapt` loop).
//!
//! `adapt` ([`AdaptSummary`]): `theta`, `levels_asked`, `target`, `reference_generation` (the flags;
//! `null` when not given), `exact` (the errors are true ones), `stopped` (why the loop stopped before its
//! goal, else `null`); `levels`, one [`AdaptLevel`] per level: `level`, `triangles`, `unknowns`,
//! `paper_dofs`, `generation` (largest bisection generation), `estimator` (η, max over the time nodes),
//! `error` (the true error, else the distance to the reference, else to the next level; `null` when none
//! is known) with `error_kind` (`true`, `vs_reference`, `vs_next`) and `effectivity` (η / error),
//! `vs_next`, `vs_reference`, `min_angle` (degrees), `marked` (triangles marked for bisection), `wall`,
//! `worst_step` (the node of the largest η), `terms` (η's terms at that node, by name), `time_estimator`
//! (the time indicator η_k = D^{1/2} + 3L, `src/adapt/time.rs`), `time_dissipation` (D^{1/2}), `time_load` (L),
//! `estimate` (the error estimate: η calibrated along the sequence, `src/adapt/estimate.rs`; `null` on level
//! 0) and `richardson` (the Richardson estimate R it is calibrated against).

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use tresca_cr::fem::norms::ErrorNorms;
use tresca_cr::stepping::SetupTimes;

/// The schema version written in `schema`; raised when a field changes meaning or goes away.
pub const SCHEMA: u32 = 1;

/// `--json FILE`, shared by the subcommands.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct JsonArg {
    /// Write a machine-readable summary (JSON; fields in src/cli/summary.rs) to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
}

/// `--json FILE` and `--force` of `check`, `study` and `plan` (`run` and `adapt` have a `--force` of their own).
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Reports {
    /// Write a machine-readable summary (JSON; fields in src/cli/summary.rs) to FILE.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Replace the files this command writes (--json; study and plan: --csv; study: --differences' files).
    #[arg(long)]
    pub force: bool,
}

/// The summary of one subcommand (see the module doc).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Summary {
    pub schema: u32,
    pub command: String,
    pub version: String,
    pub commit: String,
    pub scene: String,
    pub status: String,
    pub wall: f64,
    pub check: Option<CheckSummary>,
    pub run: Option<RunSummary>,
    pub study: Option<StudySummary>,
    pub plan: Option<PlanSummary>,
    /// Absent in summaries written before `adapt --json` existed (read as `null`).
    #[serde(default)]
    pub adapt: Option<AdaptSummary>,
}

impl Summary {
    /// An empty summary of `command` on `scene`, completed.
    pub fn new(command: &str, scene: &str, wall: f64) -> Summary {
        Summary {
            schema: SCHEMA,
            command: command.into(),
            version: env!("CARGO_PKG_VERSION").into(),
            commit: env!("TRESCA_BUILD_COMMIT").into(),
            scene: scene.into(),
            status: "completed".into(),
            wall,
            check: None,
            run: None,
            study: None,
            plan: None,
            adapt: None,
        }
    }
}

/// Refuse a `--json` path whose directory does not exist before any work is done (a long run would
/// otherwise fail at its end).
pub fn check_path(path: Option<&Path>) -> Result<()> {
    if let Some(p) = path {
        let dir = p.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
        anyhow::ensure!(dir.is_dir(), "--json {}: the directory {} does not exist", p.display(), dir.display());
        anyhow::ensure!(!p.is_dir(), "--json {}: is a directory", p.display());
    }
    Ok(())
}

/// Write `s` to `path` under the rule of every output (`output::guard::write_new`: built in `FILE.tmp`,
/// then renamed, never half written; an existing file replaced only when `force`).
pub fn write(path: &Path, s: &Summary, force: bool) -> Result<()> {
    let text = serde_json::to_string_pretty(s).context("cannot serialise the summary")?;
    Ok(tresca_cr::output::guard::write_new(path, "--json file", (text + "\n").as_bytes(), force)?)
}

/// The set-up's wall times.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Phases {
    pub space: f64,
    pub assembly: f64,
    pub factorisation: f64,
    pub superposition: f64,
    pub condensation: f64,
}

impl From<SetupTimes> for Phases {
    fn from(s: SetupTimes) -> Phases {
        let SetupTimes { space, assembly, factorisation, superposition, condensation } = s;
        Phases { space, assembly, factorisation, superposition, condensation }
    }
}

/// True errors at one time (or their max).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct Errors {
    pub energy: f64,
    pub h1: f64,
    pub l2: f64,
}

impl From<ErrorNorms> for Errors {
    fn from(e: ErrorNorms) -> Errors {
        Errors { energy: e.energy, h1: e.h1, l2: e.l2 }
    }
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct CheckSummary {
    pub vertices: usize,
    pub triangles: usize,
    pub edges: usize,
    pub h: f64,
    pub unknowns: usize,
    pub paper_dofs: usize,
    pub contact_unknowns: usize,
    pub steps: usize,
    pub solver: String,
    pub tol: f64,
    pub max_iter: usize,
    pub exact: bool,
    pub setup: Phases,
    pub memory: u64,
    pub disk: u64,
    /// The singular exponents of the scene's boundary points (`cli/corners.rs`).
    pub singular: Singular,
}

/// `check`'s singular exponents: every corner and change of condition, and the orders that follow.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Singular {
    pub points: Vec<SingularPoint>,
    /// min(1, min Re α): the energy-norm order in h of uniform refinement.
    pub uniform_order: f64,
    /// The order in N (unknowns) that adaptive refinement can reach: ½.
    pub adaptive_order: f64,
}

/// One boundary point: where, its interior angle (radians), its two parts and the pair of conditions
/// with the smallest exponent, and that exponent α (`null` when Re α ≥ 1).
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct SingularPoint {
    pub x: f64,
    pub y: f64,
    pub angle: f64,
    pub parts: [String; 2],
    pub sides: [String; 2],
    pub alpha: Option<f64>,
    pub alpha_imag: Option<f64>,
    /// α ≤ `fem::singular::FLOOR_EXPONENT`: an error floor, not a rate (a polygonised curve's vertex
    /// between sliding sides); `plan` refuses where its pilots confirm one.
    #[serde(default)]
    pub floor: bool,
}

/// One time step's statistics.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Step {
    pub n: usize,
    pub t: f64,
    pub iterations: usize,
    pub residual: f64,
    pub stick: usize,
    pub slip: usize,
    pub errors: Option<Errors>,
    /// With a unilateral or Coulomb part: the lengths of Γ_C in contact, separated, and sticking.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lengths: Option<ContactLengths>,
}

/// Lengths of Γ_C in one step (scenes with normal unknowns).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct ContactLengths {
    pub contact_length: f64,
    pub separated_length: f64,
    pub stick_length: f64,
}

impl Step {
    pub fn of(r: &tresca_cr::StepResult, space: &tresca_cr::fem::space::CrSpace) -> Step {
        Step {
            n: r.n,
            t: r.t,
            iterations: r.iterations,
            residual: r.residual,
            stick: r.n_stick(),
            slip: r.n_slip(),
            errors: r.errors.map(Errors::from),
            lengths: r.contact_lengths(space).map(|[c, s, k]| ContactLengths {
                contact_length: c,
                separated_length: s,
                stick_length: k,
            }),
        }
    }
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub refine: u32,
    pub unknowns: usize,
    pub paper_dofs: usize,
    pub contact_edges: usize,
    pub steps: usize,
    pub solver: String,
    pub tol: f64,
    pub setup: Phases,
    /// How K's fill-reducing ordering was made (`Factor::ordering`); absent in files before it was written.
    #[serde(default)]
    pub ordering: String,
    pub step_stats: Vec<Step>,
    pub iterations: usize,
    pub max_residual: f64,
    pub max_errors: Option<Errors>,
    pub output: Option<String>,
}

mod adapt;
mod plan;
mod study;
pub use adapt::{AdaptLevel, AdaptSummary, AdaptiveRoute};
pub use plan::{Achieved, PlanSummary};
pub use study::{Level, StudySummary};

#[cfg(test)]
mod tests;

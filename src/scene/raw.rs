//! The TOML tables of a scene as serde structs, one per table, unknown keys rejected. Validation and
//! expression compilation happen in the parent module.

use super::{Diagonal, Method};
use serde::Deserialize;
use std::path::PathBuf;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawScene {
    pub(super) title: Option<String>,
    pub(super) mesh: RawMeshTable,
    pub(super) material: RawMaterial,
    pub(super) boundary: Vec<RawBoundary>,
    pub(super) loads: Option<RawLoads>,
    pub(super) initial: Option<RawInitial>,
    pub(super) time: RawTime,
    pub(super) discretisation: Option<RawDisc>,
    pub(super) solver: Option<RawSolver>,
    pub(super) exact: Option<RawExact>,
    pub(super) output: Option<RawOutput>,
    /// Optional `[units]` (labels only: the solver is unit-free; `scripts/render.py` reads them from the
    /// scene text stored in the results file).
    #[allow(dead_code)]
    pub(super) units: Option<RawUnits>,
    pub(super) quantities: Option<RawQuantities>,
    /// The deprecated name of `[quantities]`.
    pub(super) outputs: Option<RawQuantities>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawQuantities {
    #[serde(default)]
    pub(super) max_slip: bool,
    #[serde(default)]
    pub(super) stick_length: bool,
    pub(super) elastic_energy: Option<bool>,
    /// The deprecated name of `elastic_energy`.
    pub(super) energy: Option<bool>,
    #[serde(default)]
    pub(super) traction_at: Vec<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
pub(super) struct RawUnits {
    pub(super) length: Option<String>,
    pub(super) force: Option<String>,
    pub(super) time: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawMeshTable {
    pub(super) corners: Option<[[f64; 2]; 4]>,
    pub(super) cells: Option<[usize; 2]>,
    pub(super) diagonal: Option<Diagonal>,
    pub(super) file: Option<PathBuf>,
    #[serde(default)]
    pub(super) refine: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub(super) struct RawMaterial {
    pub(super) E: f64,
    pub(super) nu: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawBoundary {
    pub(super) name: String,
    pub(super) kind: RawKind,
    pub(super) traction: Option<[String; 2]>,
    pub(super) g_a: Option<String>,
    /// Dirichlet data u_D(x, y, t) of a dirichlet part (default 0).
    pub(super) u: Option<[String; 2]>,
    /// Imposed normal displacement g_n(x, y, t) of a contact part (default 0).
    pub(super) gap: Option<String>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
pub(super) enum RawKind {
    Dirichlet,
    Neumann,
    Contact,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLoads {
    pub(super) f: Option<[String; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInitial {
    pub(super) u0: Option<[String; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub(super) struct RawTime {
    pub(super) T: Option<f64>,
    pub(super) steps: Option<usize>,
    pub(super) times: Option<Vec<f64>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawDisc {
    pub(super) rho: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSolver {
    pub(super) method: Option<Method>,
    pub(super) tol: Option<f64>,
    pub(super) max_iter: Option<usize>,
    pub(super) uzawa_step: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExact {
    pub(super) u: [String; 2],
    pub(super) grad: [[String; 2]; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOutput {
    pub(super) path: Option<PathBuf>,
}

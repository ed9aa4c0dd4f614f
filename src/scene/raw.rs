//! The TOML tables of a scene as serde structs, one per table, unknown keys rejected. Validation and
//! expression compilation happen in the parent module.

use super::{Diagonal, Method};
use serde::de::Error as _;
use serde::{Deserialize, Deserializer};
use std::path::PathBuf;

/// An array of exactly N values. serde's own `[T; N]` reads the first N values of a longer TOML array and
/// drops the rest without a word (`cells = [2, 2, 2]`, a third traction component), so every fixed-size
/// array of a scene is read through this: longer arrays are refused like shorter ones.
struct Exactly<T, const N: usize>([T; N]);

impl<'de, T: Deserialize<'de>, const N: usize> Deserialize<'de> for Exactly<T, N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<T>::deserialize(d)?;
        let n = v.len();
        v.try_into().map(Exactly).map_err(|_| D::Error::custom(format!("expected {N} values, found {n}")))
    }
}

/// An optional array of exactly N values ([`Exactly`]).
fn opt_exactly<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(
    d: D,
) -> Result<Option<[T; N]>, D::Error> {
    Ok(Option::<Exactly<T, N>>::deserialize(d)?.map(|a| a.0))
}

/// An array of exactly N values ([`Exactly`]).
fn exactly<'de, D: Deserializer<'de>, T: Deserialize<'de>, const N: usize>(d: D) -> Result<[T; N], D::Error> {
    Ok(Exactly::<T, N>::deserialize(d)?.0)
}

/// `[exact] grad`: exactly 2 × 2 expressions.
fn grad<'de, D: Deserializer<'de>>(d: D) -> Result<[[String; 2]; 2], D::Error> {
    Ok(Exactly::<Exactly<String, 2>, 2>::deserialize(d)?.0.map(|r| r.0))
}

/// The corners of a structured mesh: four points (x, y). The generator maps the unit square onto a
/// quadrilateral, so a polygon of other than four corners is refused rather than cut to its first four.
fn corners<'de, D: Deserializer<'de>>(d: D) -> Result<Option<[[f64; 2]; 4]>, D::Error> {
    let Some(v) = Option::<Vec<Exactly<f64, 2>>>::deserialize(d)? else { return Ok(None) };
    let n = v.len();
    let v: Vec<[f64; 2]> = v.into_iter().map(|p| p.0).collect();
    v.try_into().map(Some).map_err(|_| {
        D::Error::custom(format!(
            "a structured mesh is a quadrilateral: expected 4 corners, found {n} (other polygons need a Gmsh mesh, \
             `file`)"
        ))
    })
}

/// Points (x, y) of `[outputs] traction_at`: two finite coordinates each.
pub(super) fn points<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<[f64; 2]>, D::Error> {
    let v = Vec::<Exactly<f64, 2>>::deserialize(d)?;
    match v.iter().position(|p| !p.0.iter().all(|c| c.is_finite())) {
        Some(k) => Err(D::Error::custom(format!("point {k} ({:?}) is not finite", v[k].0))),
        None => Ok(v.into_iter().map(|p| p.0).collect()),
    }
}

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
    #[serde(default)]
    pub(super) contact_length: bool,
    #[serde(default)]
    pub(super) max_pressure: bool,
    pub(super) elastic_energy: Option<bool>,
    /// The deprecated name of `elastic_energy`.
    pub(super) energy: Option<bool>,
    #[serde(default, deserialize_with = "points")]
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
    #[serde(default, deserialize_with = "corners")]
    pub(super) corners: Option<[[f64; 2]; 4]>,
    #[serde(default, deserialize_with = "opt_exactly")]
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
    #[serde(default, deserialize_with = "opt_exactly")]
    pub(super) traction: Option<[String; 2]>,
    pub(super) g_a: Option<String>,
    /// Dirichlet data u_D(x, y, t) of a dirichlet part (default 0).
    #[serde(default, deserialize_with = "opt_exactly")]
    pub(super) u: Option<[String; 2]>,
    /// Imposed normal displacement g_n(x, y, t) of a contact part (default 0); the gap of a unilateral one.
    pub(super) gap: Option<String>,
    /// The contact law of a contact part, `"bilateral"` (default) or `"unilateral"` (read as text, so that
    /// an unknown law is refused naming the part).
    pub(super) law: Option<String>,
    /// Coulomb's friction coefficient F(x, y) of a contact part (instead of `g_a`).
    pub(super) coulomb: Option<String>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
pub(super) enum RawKind {
    Dirichlet,
    Neumann,
    Contact,
    Symmetry,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLoads {
    #[serde(default, deserialize_with = "opt_exactly")]
    pub(super) f: Option<[String; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawInitial {
    #[serde(default, deserialize_with = "opt_exactly")]
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
    #[serde(deserialize_with = "exactly")]
    pub(super) u: [String; 2],
    #[serde(deserialize_with = "grad")]
    pub(super) grad: [[String; 2]; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOutput {
    pub(super) path: Option<PathBuf>,
}

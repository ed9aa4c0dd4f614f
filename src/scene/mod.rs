//! Scene files: TOML → [`Scene`], validated, with every expression compiled once.
//!
//! One serde struct per TOML table (`deny_unknown_fields`, so a misspelt key is an error naming it).
//! [`Scene::from_str`] checks ranges (E > 0, −1 < ν < ½, ρ > 0, increasing times, ...) and compiles the
//! expressions; mesh-dependent checks (every boundary edge in exactly one part, ...) happen in `mesh`.
//! Only what the scene declares is modelled: no contact part means plain elasticity.

use crate::error::{Error, Result};
use crate::names::named_enum;
use expr::{Expr, Vec2Expr};
mod blame;
pub mod budget;
pub mod expr;
mod parts;
mod raw;
mod tables;
mod values;
pub use parts::{ContactLaw, ContactPart, FrictionBound, FrictionLaw, Part, PartKind};
pub use tables::MAX_REFINE;
use tables::{check_refine, exact, loads, material, mesh_spec, parts, quantities, solver_settings, time_grid};
pub use values::MAX_EXPR_CHARS;
use values::{at_line, line_of, positive_finite, uniform_times};

use raw::*;
use std::path::{Path, PathBuf};

pub use crate::mesh::{Diagonal, MeshSpec};

/// Isotropic material, plane strain.
#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub e: f64,
    pub nu: f64,
}

named_enum! {
    /// Per-step friction solver (`[solver] method`, `--solver`).
    pub enum Method {
        /// Semismooth Newton (projected Newton with Armijo search on the condensed dual).
        Ssn = "ssn",
        /// The paper's Uzawa iteration.
        Uzawa = "uzawa",
        /// Plain primal–dual active set (no globalisation; may cycle; diagnostics only).
        Pdas = "pdas",
    }
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct SolverSettings {
    pub method: Method,
    /// Stopping tolerance (see docs/model.md).
    pub tol: f64,
    /// Iteration limit per step; `None` = the method's default ([`SolverSettings::max_iter`]).
    pub max_iter_given: Option<usize>,
    /// The paper's Uzawa step ρ̃; 0 = automatic.
    pub uzawa_step: f64,
}

impl SolverSettings {
    /// Iteration limit per step: as given, else 100 for the Newton-type methods and 200 000 for Uzawa
    /// (a projected-gradient method whose iteration count grows with the condition number of C).
    pub fn max_iter(&self) -> usize {
        self.max_iter_given.unwrap_or(if self.method == Method::Uzawa { 200_000 } else { 100 })
    }
}

/// Exact solution and its gradient, for true errors.
#[derive(Clone, Debug)]
pub struct Exact {
    pub u: Vec2Expr,
    /// grad[i][j] = ∂u_i/∂x_j.
    pub grad: [[Expr; 2]; 2],
}

/// Scalar quantities at the final time T that `study` estimates and `plan` may target (`[quantities]`;
/// `[output]` is where the results file goes). Without the table a study reports `max_slip`,
/// `stick_length` (scenes with contact) and `elastic_energy`.
#[derive(Clone, Debug, PartialEq)]
pub struct Outputs {
    /// max over Γ_C edges of |u_τ(m_e)|.
    pub max_slip: bool,
    /// Total length of the Γ_C edges that stick in the last step.
    pub stick_length: bool,
    /// Total length of the Γ_C edges in contact (not separated) in the last step (scenes with normal
    /// unknowns only).
    pub contact_length: bool,
    /// max over Γ_C edges of the contact pressure p_e = P_e/|e| in the last step (scenes with normal
    /// unknowns only).
    pub max_pressure: bool,
    /// Elastic energy ½ a_h(u, u) (key `elastic_energy`; the old key `energy` is read with a deprecation).
    pub elastic_energy: bool,
    /// σ_τ·τ on the Γ_C edge nearest to each point.
    pub traction_at: Vec<[f64; 2]>,
}

/// A validated scene.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Where it was read from (for messages).
    pub file: String,
    /// The full scene text (stored in results files).
    pub text: String,
    pub title: String,
    pub mesh: MeshSpec,
    pub material: Material,
    pub parts: Vec<Part>,
    /// Body force; `None` if absent or zero.
    pub f: Option<Vec2Expr>,
    /// Initial displacement; `None` if absent or zero.
    pub u0: Option<Vec2Expr>,
    /// Time nodes t₀ < t₁ < … < t_N.
    pub times: Vec<f64>,
    /// True if the grid came from `T` and `steps` (so `--steps` may override it).
    pub uniform_time: bool,
    pub rho: f64,
    pub solver: SolverSettings,
    pub exact: Option<Exact>,
    pub output: Option<PathBuf>,
    /// `[quantities]`: the scalar outputs a study estimates.
    pub outputs: Option<Outputs>,
    /// Deprecated spellings the scene used, one message each (the command line prints them).
    pub deprecations: Vec<String>,
}

impl Scene {
    /// Read and validate a scene file.
    pub fn from_file(path: &Path) -> Result<Self> {
        let text = crate::input::read_text(path, "scene")?;
        let mut scene = Self::from_str(&text, &path.display().to_string())?;
        // relative mesh paths are relative to the scene file
        if let MeshSpec::Gmsh { path: p, .. } = &mut scene.mesh {
            if p.is_relative() {
                if let Some(dir) = path.parent() {
                    *p = dir.join(&*p);
                }
            }
        }
        Ok(scene)
    }

    /// Parse and validate scene text; `file` is used in messages.
    pub fn from_str(text: &str, file: &str) -> Result<Self> {
        let raw: RawScene = toml::from_str(text).map_err(|e| {
            let span = e.span().map(|s| line_of(text, s.start)).map(|l| at_line(text, l)).unwrap_or_default();
            Error::scene(file, span, e.message().to_string())
        })?;
        let mesh = mesh_spec(file, &raw.mesh)?;
        let mut deprecations = Vec::new();
        let outputs = quantities(file, raw.quantities, raw.outputs, &mut deprecations)?;
        let (e, nu) = material(file, &raw.material)?;
        let parts = parts(file, &raw.boundary)?;
        let (f, u0) = loads(file, raw.loads, raw.initial)?;
        let (times, uniform_time) = time_grid(file, raw.time)?;
        let rho = positive_finite(file, "discretisation.rho", raw.discretisation.map(|d| d.rho).unwrap_or(10.0))?;
        values::representable(file, e, nu, rho)?;
        let solver = solver_settings(file, raw.solver)?;
        let exact = exact(file, raw.exact)?;
        let scene = Scene {
            file: file.to_string(),
            text: text.to_string(),
            title: raw.title.unwrap_or_default(),
            mesh,
            material: Material { e, nu },
            parts,
            f,
            u0,
            times,
            uniform_time,
            rho,
            solver,
            exact,
            output: raw.output.and_then(|o| o.path),
            outputs,
            deprecations,
        };
        tables::normal_quantities(file, scene.outputs.as_ref(), scene.has_normal_unknowns())?;
        Ok(scene)
    }

    /// Override the number of uniform refinements (`--refine`).
    pub fn set_refine(&mut self, k: u32) -> Result<()> {
        check_refine(&self.file, "--refine", k)?;
        match &mut self.mesh {
            MeshSpec::Structured { refine, .. } | MeshSpec::Gmsh { refine, .. } => *refine = k,
        }
        Ok(())
    }

    /// Override the number of uniform steps (`--steps`); refused for an explicit `times` list.
    pub fn set_steps(&mut self, n: usize) -> Result<()> {
        if !self.uniform_time {
            return Err(Error::scene(
                &self.file,
                "--steps",
                "the scene gives an explicit `times` list; --steps would discard it",
            ));
        }
        let t0 = self.times[0];
        let t = *self.times.last().expect("at least two nodes") - t0;
        self.times = uniform_times(&self.file, t, n)?.into_iter().map(|s| s + t0).collect();
        Ok(())
    }

    /// The number of uniform refinements of the mesh.
    pub fn mesh_level(&self) -> u32 {
        match &self.mesh {
            MeshSpec::Structured { refine, .. } | MeshSpec::Gmsh { refine, .. } => *refine,
        }
    }

    /// True if a part imposes nonzero boundary data (u_D or g_n; see [`PartKind`]).
    pub fn has_boundary_data(&self) -> bool {
        self.parts.iter().any(|p| p.kind.has_data())
    }

    /// True if the scene has a contact part.
    pub fn has_contact(&self) -> bool {
        self.parts.iter().any(|p| matches!(p.kind, PartKind::Contact(..)))
    }

    /// True if the Γ_C edges carry normal unknowns (a unilateral or a Coulomb part:
    /// [`ContactPart::normal_unknown`]).
    pub fn has_normal_unknowns(&self) -> bool {
        self.parts.iter().any(|p| p.kind.contact().is_some_and(|c| c.normal_unknown))
    }
}

//! Scene files: TOML → [`Scene`], validated, with every expression compiled once.
//!
//! One serde struct per TOML table (`deny_unknown_fields`, so a misspelt key is an error naming it).
//! [`Scene::from_str`] checks ranges (E > 0, −1 < ν < ½, ρ > 0, increasing times, ...) and compiles the
//! expressions; mesh-dependent checks (every boundary edge in exactly one part, ...) happen in `mesh`.
//! Only what the scene declares is modelled: no contact part means plain elasticity.

use crate::error::{Error, Result};
use expr::{Expr, Vec2Expr};
pub mod budget;
pub mod expr;
mod parts;
mod raw;
mod values;
pub use parts::{FrictionBound, Part, PartKind};
pub use values::MAX_EXPR_CHARS;
use values::{line_of, positive_finite, sized, uniform_times};

use raw::*;
use serde::Deserialize;
use std::path::{Path, PathBuf};

pub use crate::mesh::{Diagonal, MeshSpec};

/// Isotropic material, plane strain.
#[derive(Clone, Copy, Debug)]
pub struct Material {
    pub e: f64,
    pub nu: f64,
}

/// Per-step friction solver.
#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
pub enum Method {
    /// Semismooth Newton (projected Newton with Armijo search on the condensed dual).
    Ssn,
    /// The paper's Uzawa iteration.
    Uzawa,
    /// Plain primal–dual active set (no globalisation; may cycle; diagnostics only).
    Pdas,
}

impl Method {
    /// Name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Ssn => "ssn",
            Method::Uzawa => "uzawa",
            Method::Pdas => "pdas",
        }
    }
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct SolverSettings {
    pub method: Method,
    /// Stopping tolerance (see README).
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

/// Scalar outputs a study estimates (`[outputs]`), all at the final time T. Without the table a study
/// reports `max_slip`, `stick_length` (scenes with contact) and `energy`.
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outputs {
    /// max over Γ_C edges of |u_τ(m_e)|.
    #[serde(default)]
    pub max_slip: bool,
    /// Total length of the Γ_C edges that stick in the last step.
    #[serde(default)]
    pub stick_length: bool,
    /// Elastic energy ½ a_h(u, u).
    #[serde(default)]
    pub energy: bool,
    /// σ_τ·τ on the Γ_C edge nearest to each point.
    #[serde(default, deserialize_with = "raw::points")]
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
    /// `[outputs]`: the scalar outputs a study estimates.
    pub outputs: Option<Outputs>,
}

fn nonzero(v: Option<Vec2Expr>) -> Option<Vec2Expr> {
    v.filter(|e| !e.is_zero())
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
            let span = e.span().map(|s| line_of(text, s.start)).map(|l| format!("line {l}")).unwrap_or_default();
            Error::scene(file, span, e.message().to_string())
        })?;
        let mesh = match (&raw.mesh.file, raw.mesh.corners, raw.mesh.cells) {
            (Some(p), None, None) => {
                if raw.mesh.diagonal.is_some() {
                    return Err(Error::scene(file, "mesh.diagonal", "only for structured meshes"));
                }
                MeshSpec::Gmsh { path: p.clone(), refine: raw.mesh.refine }
            }
            (None, Some(corners), Some(cells)) => {
                if cells[0] == 0 || cells[1] == 0 {
                    return Err(Error::scene(file, "mesh.cells", "cell counts must be at least 1"));
                }
                if corners.iter().flatten().any(|c| !c.is_finite()) {
                    return Err(Error::scene(file, "mesh.corners", "corners must be finite"));
                }
                let diagonal = raw.mesh.diagonal.unwrap_or(Diagonal::First);
                MeshSpec::Structured { corners, cells, diagonal, refine: raw.mesh.refine }
            }
            _ => {
                return Err(Error::scene(
                    file,
                    "mesh",
                    "give either `file` (Gmsh) or both `corners` and `cells` (structured), not both",
                ))
            }
        };
        if raw.mesh.refine > 12 {
            return Err(Error::scene(
                file,
                "mesh.refine",
                format!("{} refinements is beyond any machine", raw.mesh.refine),
            ));
        }
        let e = positive_finite(file, "material.E", raw.material.E)?;
        let nu = raw.material.nu;
        if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
            return Err(Error::scene(file, "material.nu", format!("must satisfy -1 < nu < 0.5, got {nu}")));
        }
        let mut parts = Vec::new();
        for (i, b) in raw.boundary.iter().enumerate() {
            let key = |k: &str| format!("boundary[{i}] ({}).{k}", b.name);
            if parts.iter().any(|p: &Part| p.name == b.name) {
                return Err(Error::scene(file, key("name"), "boundary part named twice"));
            }
            if b.traction.is_some() && b.kind != RawKind::Neumann {
                return Err(Error::scene(file, key("traction"), "only neumann parts take a traction"));
            }
            if b.g_a.is_some() && b.kind != RawKind::Contact {
                return Err(Error::scene(file, key("g_a"), "only contact parts take a friction bound g_a"));
            }
            let kind = match b.kind {
                RawKind::Dirichlet => PartKind::Dirichlet,
                RawKind::Neumann => PartKind::Neumann(match &b.traction {
                    Some(g) => nonzero(Some(Vec2Expr::parse(&key("traction"), sized(file, &key("traction"), g)?)?)),
                    None => None,
                }),
                RawKind::Contact => {
                    let text =
                        b.g_a.as_deref().ok_or_else(|| Error::scene(file, key("g_a"), "contact part needs g_a"))?;
                    sized(file, &key("g_a"), &[text.to_string()])?;
                    PartKind::Contact(FrictionBound::parse(file, &key("g_a"), text)?)
                }
            };
            parts.push(Part { name: b.name.clone(), kind });
        }
        if !parts.iter().any(|p| matches!(p.kind, PartKind::Dirichlet)) {
            return Err(Error::scene(
                file,
                "boundary",
                "no dirichlet part: rigid motions are not fixed (the paper requires meas(Γ_D) > 0)",
            ));
        }
        let f = match raw.loads.and_then(|l| l.f) {
            Some(f) => nonzero(Some(Vec2Expr::parse("loads.f", sized(file, "loads.f", &f)?)?)),
            None => None,
        };
        let u0 = match raw.initial.and_then(|l| l.u0) {
            Some(u) => {
                let u = Vec2Expr::parse("initial.u0", sized(file, "initial.u0", &u)?)?;
                if u.depends_on_t() {
                    return Err(Error::scene(file, "initial.u0", "must not depend on t"));
                }
                nonzero(Some(u))
            }
            None => None,
        };
        let (times, uniform_time) = match (raw.time.T, raw.time.steps, raw.time.times) {
            (Some(t), Some(n), None) => {
                let t = positive_finite(file, "time.T", t)?;
                (uniform_times(file, t, n)?, true)
            }
            (None, None, Some(ts)) => {
                if ts.len() < 2 {
                    return Err(Error::scene(file, "time.times", "needs at least two time nodes"));
                }
                for (k, w) in ts.windows(2).enumerate() {
                    if !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]) {
                        return Err(Error::scene(
                            file,
                            "time.times",
                            format!(
                                "must be finite and strictly increasing: times[{k}] = {}, times[{}] = {}",
                                w[0],
                                k + 1,
                                w[1]
                            ),
                        ));
                    }
                }
                (ts, false)
            }
            _ => return Err(Error::scene(file, "time", "give either `T` and `steps`, or `times`")),
        };
        let rho = positive_finite(file, "discretisation.rho", raw.discretisation.map(|d| d.rho).unwrap_or(10.0))?;
        values::representable(file, e, nu, rho)?;
        let rs = raw.solver.unwrap_or(RawSolver { method: None, tol: None, max_iter: None, uzawa_step: None });
        let method = rs.method.unwrap_or(Method::Ssn);
        let solver = SolverSettings {
            method,
            tol: positive_finite(file, "solver.tol", rs.tol.unwrap_or(1e-12))?,
            max_iter_given: match rs.max_iter {
                Some(0) => return Err(Error::scene(file, "solver.max_iter", "must be at least 1")),
                other => other,
            },
            uzawa_step: match rs.uzawa_step {
                Some(s) if !(s.is_finite() && s >= 0.0) => {
                    return Err(Error::scene(
                        file,
                        "solver.uzawa_step",
                        format!("must be >= 0 (0 = automatic), got {s}"),
                    ))
                }
                Some(s) => s,
                None => 0.0,
            },
        };
        let exact = match raw.exact {
            Some(x) => {
                sized(file, "exact.u", &x.u)?;
                for row in &x.grad {
                    sized(file, "exact.grad", row)?;
                }
                let g = |i: usize, j: usize| Expr::parse(&format!("exact.grad[{i}][{j}]"), &x.grad[i][j]);
                Some(Exact { u: Vec2Expr::parse("exact.u", &x.u)?, grad: [[g(0, 0)?, g(0, 1)?], [g(1, 0)?, g(1, 1)?]] })
            }
            None => None,
        };
        Ok(Scene {
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
            outputs: raw.outputs,
        })
    }

    /// Override the number of uniform refinements (`--refine`).
    pub fn set_refine(&mut self, k: u32) -> Result<()> {
        if k > 12 {
            return Err(Error::scene(&self.file, "--refine", format!("{k} refinements is beyond any machine")));
        }
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

    /// True if the scene has a contact part.
    pub fn has_contact(&self) -> bool {
        self.parts.iter().any(|p| matches!(p.kind, PartKind::Contact(_)))
    }
}

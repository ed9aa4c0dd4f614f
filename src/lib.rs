//! # tresca-cr
//!
//! Quasi-static bilateral contact with Tresca friction for 2D plane-strain linear elasticity, discretised
//! by the jump-stabilised lowest-order Crouzeix–Raviart element and backward Euler (Porwal & Wadhawan).
//!
//! The pipeline, one folder or file per stage:
//!
//! | stage | module | job |
//! |---|---|---|
//! | scene | [`scene`] | TOML → validated [`scene::Scene`]; expressions ([`scene::expr`]) |
//! | mesh | [`mesh`] | structured or Gmsh triangles, refinement, boundary parts |
//! | space | [`fem`] | V_h ([`fem::space`]), the elasticity law, K, loads, norms, prolongation |
//! | linear solves | [`solve`] | K factored once, condensation C = EᵀK⁻¹E, free response u_f = K⁻¹lⁿ |
//! | friction | [`friction`] | the per-step box QP on Γ_C by SSN, Uzawa or PDAS |
//! | time stepping | [`stepping`] | set-up once, then backward Euler steps |
//! | studies | [`study`] | convergence studies, observed orders, error estimates without an exact solution (Richardson, GCI) |
//! | adaptivity | [`adapt`] | error indicator, Dörfler marking, bisection between whole runs |
//! | planning | [`plan`] | target accuracy → the cheapest (refine, steps, solver, tolerance), from pilot runs |
//! | output | [`output`] | HDF5 results (`/tresca`, VTKHDF, XDMF), resume |
//!
//! Each backward-Euler step solves
//! uⁿ = argmin_{v ∈ V_h} ½ a_h(v,v) − (lⁿ, v) + Σ_{e ⊂ Γ_C} |e| ḡ_e |v_τ(m_e) − uⁿ⁻¹_τ(m_e)|.

pub mod adapt;
pub mod error;
pub mod fem;
pub mod friction;
pub mod input;
pub mod machine;
pub mod mesh;
pub mod names;
pub mod output;
pub mod parallel;
pub mod plan;
pub mod scene;
pub mod solve;
pub mod sparse;
pub mod stepping;
pub mod study;
pub mod threads;

pub use error::{Error, Result};
pub use scene::Scene;
pub use stepping::{Problem, RunOptions, StepResult};

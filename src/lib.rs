//! # tresca-cr
//!
//! Quasi-static bilateral contact with Tresca friction for 2D plane-strain linear elasticity, discretised
//! by the jump-stabilised lowest-order Crouzeix–Raviart element and backward Euler (Porwal & Wadhawan).
//!
//! The pipeline, one module per stage:
//! `scene` (TOML → validated [`scene::Scene`]) → `mesh` → `cr` (the space V_h) → `assemble` (K, loads)
//! → `contact` (condensed friction QP) solved by `ssn` / `uzawa` / `pdas` → `stepping` (backward Euler)
//! → `norms` (true errors) → `output` (HDF5).
//!
//! Each backward-Euler step solves
//! uⁿ = argmin_{v ∈ V_h} ½ a_h(v,v) − (lⁿ, v) + Σ_{e ⊂ Γ_C} |e| ḡ_e |v_τ(m_e) − uⁿ⁻¹_τ(m_e)|.

pub mod assemble;
pub mod contact;
pub mod cr;
pub mod error;
pub mod expr;
pub mod factor;
pub mod mesh;
pub mod norms;
pub mod output;
pub mod parallel;
pub mod pdas;
pub mod prolong;
pub mod quadrature;
pub mod scene;
pub mod ssn;
pub mod stepping;
pub mod study;
pub mod superpose;
pub mod uzawa;

pub use error::{Error, Result};
pub use scene::Scene;
pub use stepping::{Problem, StepResult};

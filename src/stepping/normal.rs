//! The normal condition of the steps of a scene with normal unknowns (a unilateral or Coulomb part,
//! `friction::normal`): its per-step state, step 0's (with the refusal of a penetrating u⁰), the lengths
//! of Γ_C in contact, separated and sticking, and a step's energy with the normal forces.

use super::{Parts, Problem, StepResult};
use crate::error::Result;
use crate::fem::space::CrSpace;
use crate::friction::EdgeState;
use crate::sparse::dot;

/// The normal condition of a step on the Γ_C edges with normal unknowns (`friction::normal`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NormalState {
    /// Normal force P_e = |e| p_e (p the contact pressure; the reaction of u·n = g on a bilateral edge).
    pub force: Vec<f64>,
    /// u_n(m_e) − ḡ_e.
    pub gap: Vec<f64>,
    /// Separated (P_e = 0, open gap).
    pub separated: Vec<bool>,
}

impl StepResult {
    /// With normal unknowns, the lengths of Γ_C in contact (not separated), separated, and sticking
    /// in contact (`None` without normal unknowns).
    pub fn contact_lengths(&self, space: &CrSpace) -> Option<[f64; 3]> {
        if self.normal.force.is_empty() {
            return None;
        }
        let mut l = [0.0; 3];
        for ((c, &sep), &st) in space.contact.iter().zip(&self.normal.separated).zip(&self.state) {
            let k = if sep { 1 } else { 0 };
            l[k] += c.length;
            if !sep && st == EdgeState::Stick {
                l[2] += c.length;
            }
        }
        Some(l)
    }
}

impl Problem {
    /// a_h(u, u) of a step with u: (l, u) − Σ_e μ_e s_e, since K u = l − Eμ; with normal unknowns
    /// (l, u) − λ·Eᵀu (λ = (μ, P), Eᵀu the contact unknowns of u).
    pub(super) fn energy_of(&self, load: &[f64], r: &StepResult) -> f64 {
        if r.normal.force.is_empty() {
            return dot(load, &r.u) - dot(&r.mu, &r.slip);
        }
        let trace: Vec<f64> = self.space.contact_dofs().iter().map(|&k| r.u[k]).collect();
        dot(load, &r.u) - dot(&r.forces(), &trace)
    }
}

/// The normal state of step 0: no force, the gap of u⁰ (refused where it penetrates a unilateral part,
/// `fem::gap::check_initial`); empty without normal unknowns.
pub(super) fn initial_normal(d: Parts<'_>, u: &[f64]) -> Result<NormalState> {
    let normal = d.space.normal_edges();
    if normal.is_empty() {
        return Ok(NormalState::default());
    }
    crate::fem::gap::check_initial(d.scene, d.mesh, d.space, u)?;
    let g = crate::fem::gap::GapMeans::new(d.scene, d.mesh, d.space).at(d.scene.times[0])?;
    let un: Vec<f64> = normal.iter().map(|&j| u[d.space.contact[j].normal_dof.expect("normal")]).collect();
    let gap: Vec<f64> = un.iter().zip(&g).map(|(un, g)| un - g).collect();
    let unilateral: Vec<bool> = normal.iter().map(|&j| d.space.contact[j].unilateral).collect();
    let separated = initially_separated(&unilateral, &un, &g);
    Ok(NormalState { force: vec![0.0; normal.len()], gap, separated })
}

/// Step 0's separated edges: the rule of the later steps (`friction::normal`: P_e = 0 and
/// r_e − ḡ_e < −1e-9 max|d|) with P = 0 and, as there is no step problem d, the scale
/// max_e max(|u⁰·n(m_e)|, |ḡ_e(t₀)|) over Γ_C: a unilateral edge whose gap is open by more than 1e-9 of
/// it (rounding of the edge means of u⁰ and g is ~1e-16 of it, and is not a gap).
pub(super) fn initially_separated(unilateral: &[bool], un: &[f64], g: &[f64]) -> Vec<bool> {
    let scale = un.iter().chain(g).fold(0.0f64, |a, v| a.max(v.abs()));
    unilateral.iter().zip(un.iter().zip(g)).map(|(&uni, (un, g))| uni && un - g < -1e-9 * scale).collect()
}

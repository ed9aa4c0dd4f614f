//! The condensed problem with normal unknowns (scenes with a unilateral or a Coulomb part): every Γ_C
//! edge e carries the tangential unknown s_e and the normal unknown r_e = u_n(m_e), and the contact force
//! on the body is −μ_e τ_e − P_e n_e (μ_e the friction force, P_e = |e| p_e the normal force). With
//! E the injection of both, C = EᵀK⁻¹E (one row per contact unknown, tangential ones first) and
//!   d = (s_f − s_old, r_f − ḡ),   λ = (μ, P),   Δ = d − Cλ = (Δs, r − ḡ),
//! a step solves:
//!
//! * unilateral normal: P_e ≥ 0, r_e − ḡ_e ≤ 0, P_e (r_e − ḡ_e) = 0; bilateral normal: r_e = ḡ_e
//!   (P_e free: the reaction of u·n = g, of either sign);
//! * Tresca: |μ_e| ≤ w_e = |e| ḡa_e with μ_e ∈ w_e ∂|·|(Δs_e), on every Γ_C edge (also where it is
//!   separated: the Signorini–Tresca model). This is the dual QP min ½λᵀCλ − dᵀλ over the bounds
//!   μ_e ∈ [−w_e, w_e], P_e ∈ [0, +∞) (unilateral) or (−∞, +∞) (bilateral), solved with `method = "ssn"`
//!   by the safeguarded primal–dual active-set method of [`super::hik`], or by `pdas` ([`super::Qp`]).
//! * Coulomb: the same with the threshold F̄_e |P_e| in place of w_e (zero on a separated edge):
//!   no longer a QP; solved by the semismooth Newton method of [`super::coulomb`].
//!
//! An edge is *separated* when P_e = 0 and its gap is open, r_e − ḡ_e < −1e-9 · max|d| (the scale
//! [`super::classify`] uses for a nonzero slip).

use super::nested::Levels;
use super::{classify_with, coulomb, hik, not_converged, pdas, pow2_scale, scaled, Friction, FrictionSolution, Qp};
use crate::error::Result;
use crate::fem::gap::GapMeans;
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::{Method, Scene};
use nalgebra::DMatrix;

/// The normal unknowns of a run: their bounds, Coulomb's coefficients and the gaps.
pub struct Normal {
    /// Lower bound of each normal force: 0 (unilateral) or −∞ (bilateral).
    pub(super) lo: Vec<f64>,
    /// F̄_e of each Γ_C edge (`None`: Tresca's bound).
    pub(super) coulomb: Vec<Option<f64>>,
    gaps: GapMeans,
    /// The coarse levels of the active-set predictor (`super::nested`).
    levels: Levels,
}

impl Normal {
    /// The normal unknowns of `space` (`None` without: every Γ_C edge has one in a scene with a
    /// unilateral or Coulomb part, none otherwise).
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Option<Normal> {
        if space.normal_edges().len() != space.contact.len() || space.contact.is_empty() {
            return None;
        }
        Some(Normal {
            lo: space.contact.iter().map(|c| if c.unilateral { 0.0 } else { f64::NEG_INFINITY }).collect(),
            coulomb: space.contact.iter().map(|c| c.coulomb).collect(),
            gaps: GapMeans::new(scene, mesh, space),
            levels: Levels::new(mesh, space),
        })
    }

    /// ḡ_e(t) of every Γ_C edge.
    pub fn gaps(&self, t: f64) -> Result<Vec<f64>> {
        self.gaps.at(t)
    }

    /// True if some edge has Coulomb friction.
    pub fn has_coulomb(&self) -> bool {
        self.coulomb.iter().any(|f| f.is_some())
    }

    /// Solve step n (time t): d and λ₀ = (μ₀, P₀) in the order of the module doc.
    /// `c` is C (C + ρGGᵀ for a floating body, `super::floating`).
    pub(super) fn solve(
        &self,
        fr: &Friction,
        c: &DMatrix<f64>,
        d: &[f64],
        mu0: &[f64],
        n: usize,
        t: f64,
    ) -> Result<FrictionSolution> {
        let nc = fr.w.len();
        let (k, zeroed, w, d, mu0) = scaled(c, &fr.w, d, mu0);
        if zeroed {
            fr.zeroed.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        let lo: Vec<f64> = w.iter().map(|w| -w).chain(self.lo.iter().copied()).collect();
        let hi: Vec<f64> = w.iter().copied().chain(std::iter::repeat_n(f64::INFINITY, nc)).collect();
        let qp = Qp { c, d: &d, lo: &lo, hi: &hi };
        let s = &fr.settings;
        let sol = if self.has_coulomb() {
            coulomb::solve(&qp, &self.coulomb, &w, &mu0, s.tol, (&self.levels, s.max_iter()))
        } else if s.method == Method::Pdas {
            pdas::solve(&qp, &mu0, s.tol, s.max_iter())
        } else {
            hik::solve(&qp, &mu0, s.tol, s.max_iter(), &self.levels)
        };
        let (lam, iterations, residual) = sol.map_err(|e| not_converged(e, n, t, s.tol))?;
        let ds = qp.slip_increment(&lam);
        let thr: Vec<f64> = (0..nc).map(|e| coulomb::threshold(&self.coulomb, &w, e, lam[nc + e])).collect();
        let state = classify_with(&thr, &d, &lam[..nc], &ds[..nc]);
        let scale = ds.iter().chain(&d).fold(0.0f64, |a, v| a.max(v.abs()));
        let separated =
            (0..nc).map(|e| self.lo[e] == 0.0 && lam[nc + e] <= 0.0 && ds[nc + e] < -1e-9 * scale).collect();
        let back = |v: &[f64]| -> Vec<f64> { v.iter().map(|&x| if k == 0 { x } else { pow2_scale(x, k) }).collect() };
        Ok(FrictionSolution {
            mu: back(&lam[..nc]),
            slip_increment: back(&ds[..nc]),
            state,
            iterations,
            residual,
            normal: back(&lam[nc..]),
            gap: back(&ds[nc..]),
            separated,
            rigid: vec![],
        })
    }
}

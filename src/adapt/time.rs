//! The time indicator: a bound on the error of backward Euler in time, beside the space indicator.
//!
//! **Derivation.** Fix the mesh. The space-discrete, time-continuous problem is the rate-independent
//! inclusion ℓ(t) − K u(t) ∈ ∂Ψ(u̇(t)), Ψ(v) = Σ_e ḡ_e |s_e(v)| (Tresca: a positively 1-homogeneous
//! dissipation on the contact unknowns; K u = ℓ − Eμ, so λ = ℓ − K u = Eμ and ⟨λ, v⟩ = μ·s(v)). Backward
//! Euler gives uⁿ with λⁿ = ℓⁿ − K uⁿ ∈ ∂Ψ(Δuⁿ). Compare u with the piecewise linear interpolant û of
//! the uⁿ, and ℓ with the interpolant ℓ̄ of the ℓⁿ, following the residual argument of Nochetto–Savaré–
//! Verdi (2000, "A posteriori error estimates for variable time-step discretizations of nonlinear
//! evolution equations", CPAM 53) in its rate-independent form (the time terms of Alberty–Carstensen
//! 2000, "Numerical analysis of time-depending primal elastoplasticity with hardening", SINUM 37): on a
//! step, λ̂(t) = ℓ̄ − Kû is the convex combination θλⁿ⁻¹ + (1 − θ)λⁿ, θ = (tₙ − t)/k, so it lies in the
//! set K* = ∂Ψ(0) (|μ_e| ≤ ḡ_e), and for e = u − û, with ⟨λ, u̇⟩ = Ψ(u̇) and ⟨λ̂, w⟩ ≤ Ψ(w),
//!
//!   ⟨Ke, ė⟩ = ⟨ℓ − ℓ̄, ė⟩ + ⟨λ̂ − λ, u̇ − û̇⟩ ≤ ⟨ℓ − ℓ̄, ė⟩ + Ψ(û̇) − ⟨λ̂, û̇⟩ = ⟨ℓ − ℓ̄, ė⟩ + θ ⟨Δλⁿ, Δuⁿ⟩/k.
//!
//! Integrated over [0, tₙ] (∫θ = k/2 per step; e(0) = 0: step 0 is the static solution at t₀; ℓ = ℓ̄
//! at the nodes, so ∫⟨ℓ − ℓ̄, ė⟩ = −∫⟨ℓ̇ − ℓ̄̇, e⟩), with D = Σ_m ⟨Δλᵐ, Δuᵐ⟩ = Σ_m Δμᵐ·Δsᵐ ≥ 0 (each
//! term ≥ 0: the monotonicity of ∂Ψ), L = ∫₀ᵀ ‖ℓ̇ − ℓ̄̇‖_* (‖r‖_*² = rᵀK⁻¹r, the dual of |||·|||) and
//! M = max_t |||e(t)||| (also between the nodes, where ⟨ℓ − ℓ̄, e⟩ ≤ (L/2) M adds to the bound):
//! ½M² ≤ ½D + (3/2) L M, hence
//!
//!   max_n |||u(tₙ) − uⁿ||| ≤ η_k := D^{1/2} + 3L.
//!
//! D is the dissipation mismatch of the steps in which the friction force changes while Γ_C slips; L
//! measures how far the loads are from affine within a step (zero for loads affine in t, as in Example
//! 5.1). Accumulation: an ℓ² sum over the steps (D), so η_k bounds the max over the time nodes, as the
//! space indicator η = max_n ηⁿ does; the total error is at most the space error plus η_k.
//!
//! L is computed per step on `SUBSTEPS` equal sub-intervals, Σ_j ‖Δ_jℓ − Δℓ/SUBSTEPS‖_* (a lower
//! approximation of the integral by the triangle inequality, exact for loads affine on each
//! sub-interval); a sub-interval whose residual is below 1e-12 of the step's load change (the rounding
//! of an affine load) counts as 0 and skips its solve.
//!
//! **Dirichlet data.** With boundary data (`fem::lifting`) the unknowns are w and the displacement is
//! w + u_L(t); the load of w carries the lifting's part b_D − a_h(u_L, ·), whose dual norm is the energy
//! of the lifting's zero extension (one layer of triangles: ∝ 1/h) less that of its discrete harmonic
//! extension, and grows under refinement. The error to bound is that of the full displacement, so the
//! term of a sub-interval is the energy of the full field X = (K⁻¹r + u_L(δ), δ), δ the sub-interval's
//! non-affinity of the data and r that of the whole load: ‖X‖² = A(U, U) − 2B(δ, U) + C(δ, δ)
//! (`fem::forms`) = ‖r_{f,g}‖²_* + the energy of the discrete harmonic extension of δ, bounded under
//! refinement.

use crate::error::Result;
use crate::fem::forms::{dot2, FullForm};
use crate::fem::lifting::DataValues;
use crate::stepping::{Problem, StepResult};

/// Sub-intervals per step for L.
pub const SUBSTEPS: usize = 4;

/// A time node as the indicator keeps it: t, ℓ(t), μ, s.
type Node = (f64, Vec<f64>, Vec<f64>, Vec<f64>);

/// The time indicator accumulated over the steps of a run.
#[derive(Clone, Debug, Default)]
pub struct TimeIndicator {
    /// D = Σ_m Δμᵐ·Δsᵐ.
    pub dissipation: f64,
    /// L = Σ_m ∫ ‖ℓ̇ − ℓ̄̇‖_* over step m.
    pub load: f64,
    /// The previous node: t, ℓ, μ, s.
    prev: Option<Node>,
}

impl TimeIndicator {
    /// η_k = D^{1/2} + 3L (module doc).
    pub fn value(&self) -> f64 {
        self.dissipation.max(0.0).sqrt() + 3.0 * self.load
    }

    /// Add the step ending at node `r` (the first node only starts the sum).
    pub fn push(&mut self, p: &Problem, r: &StepResult) -> Result<()> {
        let loads = p.free.loads();
        let mut l_n = Vec::new();
        loads.assemble(r.t, &mut l_n)?;
        if let Some((t0, l0, mu0, s0)) = &self.prev {
            let d: f64 =
                r.mu.iter().zip(mu0).zip(r.slip.iter().zip(s0)).map(|((m, m0), (s, s1))| (m - m0) * (s - s1)).sum();
            self.dissipation += d;
            self.load += load_oscillation(p, *t0, r.t, l0, &l_n)?;
        }
        self.prev = Some((r.t, l_n, r.mu.clone(), r.slip.clone()));
        Ok(())
    }
}

/// a + s (b − c) for data values (the same shapes).
fn data_affine(a: &DataValues, b: &DataValues, c: &DataValues, s: f64) -> DataValues {
    let d = b.minus(c);
    DataValues {
        d: a.d
            .iter()
            .zip(&d.d)
            .map(|(x, y)| [0, 1, 2].map(|q| [x[q][0] + s * y[q][0], x[q][1] + s * y[q][1]]))
            .collect(),
        g: a.g.iter().zip(&d.g).map(|(x, y)| [0, 1, 2].map(|q| x[q] + s * y[q])).collect(),
    }
}

/// The energy norm of the full field X = (K⁻¹r + u_L(δ), δ) of a sub-interval (module doc), given
/// x = K⁻¹r and the data's non-affinity δ.
fn full_energy(p: &Problem, forms: &FullForm, x: &[f64], delta: &DataValues) -> f64 {
    let mut u = p.space.midpoint_values(x);
    if let Some(data) = &p.data {
        data.add_lifting(&p.space.contact, delta, &mut u);
    }
    let au = forms.apply(&p.mesh, &u);
    let bd = forms.data_vector(delta, u.len());
    (dot2(&au, &u) - 2.0 * dot2(&bd, &u) + forms.data_data(delta, delta)).max(0.0).sqrt()
}

/// Σ_j ‖Δ_jℓ − Δℓ/SUBSTEPS‖_* over the sub-intervals of [t0, t1], with Dirichlet data the energy of the
/// full field instead (module doc).
fn load_oscillation(p: &Problem, t0: f64, t1: f64, l0: &[f64], l1: &[f64]) -> Result<f64> {
    let forms = p.data.as_ref().map(|d| FullForm::new(&p.mesh, &p.space, Some(d), &p.law, p.scene.rho));
    let ends = match &p.data {
        Some(d) => Some((d.values(t0)?, d.values(t1)?)),
        None => None,
    };
    let mut data_before = ends.as_ref().map(|e| e.0.clone());
    let dl: Vec<f64> = l1.iter().zip(l0).map(|(a, b)| (a - b) / SUBSTEPS as f64).collect();
    let scale = SUBSTEPS as f64 * dl.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (mut before, mut at, mut sum) = (l0.to_vec(), Vec::new(), 0.0);
    for j in 1..=SUBSTEPS {
        if j == SUBSTEPS {
            at = l1.to_vec();
        } else {
            p.free.loads().assemble(t0 + (t1 - t0) * j as f64 / SUBSTEPS as f64, &mut at)?;
        }
        let r: Vec<f64> = at.iter().zip(&before).zip(&dl).map(|((a, b), d)| a - b - d).collect();
        let big = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if big > 1e-12 * scale && big > 0.0 {
            let mut x = r.clone();
            p.free.factor().solve_in_place(&mut x);
            sum += match (&forms, &ends, &p.data) {
                (Some(forms), Some((d0, d1)), Some(data)) => {
                    // δ = Δ_j data − Δ data / SUBSTEPS
                    let at_j = data.values(t0 + (t1 - t0) * j as f64 / SUBSTEPS as f64)?;
                    let prev = data_before.replace(at_j.clone()).expect("data before");
                    let step = data_affine(&at_j.minus(&prev), d0, d1, 1.0 / SUBSTEPS as f64);
                    full_energy(p, forms, &x, &step)
                }
                _ => r.iter().zip(&x).map(|(a, b)| a * b).sum::<f64>().max(0.0).sqrt(),
            };
        } else if let (Some(data), Some(b)) = (&p.data, data_before.as_mut()) {
            *b = data.values(t0 + (t1 - t0) * j as f64 / SUBSTEPS as f64)?;
        }
        std::mem::swap(&mut before, &mut at);
    }
    Ok(sum)
}

//! The condensed problem of a floating body (`solve::kernel`): with u = K⁺(l − Eλ) + Rα, C = EᵀK⁺E,
//! G = EᵀR (orthonormal columns) and e = Rᵀl, a step solves the friction problem of the other modules
//! with Δ = d − Cλ + Gα and the equilibrium of the rigid motions
//!   Gᵀλ = e,
//! whose multiplier is α (for a QP: min ½λᵀCλ − dᵀλ over the bounds and Gᵀλ = e).
//!
//! It is solved by the method of multipliers (augmented Lagrangian, Hestenes–Powell): each outer
//! iteration solves the problem of the other modules, unchanged, with
//!   C_ρ = C + ρGGᵀ,   d_ρ = d + G(α + ρe),
//! and updates α ← α + ρ(e − Gᵀλ). Its Δ_ρ = d_ρ − C_ρλ is Δ of the updated α exactly, so the friction
//! law holds at every outer iteration and only the equality is iterated on; its residual
//! max_j |e_j − (Gᵀλ)_j| / (Σ_i |G_ij| · F) (F the size of λ) is driven to the solver's tolerance, the
//! answer of the exact problem to that tolerance (no penalty is left in it). Where no λ within the
//! bounds balances the loads (the body would fly away or turn), the equality residual stops shrinking:
//! the step is refused naming the rigid motion along which the loads are unbalanced.

use super::{Friction, FrictionSolution};
use crate::error::{Error, Result};
use crate::solve::kernel::Motions;
use nalgebra::DMatrix;

/// ρ = AUGMENT · max_e C_ee (G has orthonormal columns): the equality is weighted well above the
/// flexibility of the contact, so an outer iteration reduces its residual by orders of magnitude.
const AUGMENT: f64 = 1e4;
/// Outer iterations at most.
const MAX_OUTER: usize = 200;
/// Outer iterations in a row that reduce the equality residual by less than half: the loads are
/// unbalanced (a feasible problem contracts much faster, see [`AUGMENT`]).
const STALLED: usize = 8;

/// The rigid motions of a floating body in the condensed problem.
pub struct Floating {
    /// G = EᵀR, one row per contact unknown (tangential first, then normal).
    g: DMatrix<f64>,
    rho: f64,
    /// C + ρGGᵀ.
    pub(super) c_rho: DMatrix<f64>,
    motions: Motions,
}

impl Floating {
    /// The equality of the rigid motions `motions` with trace `g` on the contact unknowns of `c`.
    pub fn new(c: &DMatrix<f64>, g: DMatrix<f64>, motions: Motions) -> Floating {
        let top = (0..c.nrows()).map(|i| c[(i, i)]).fold(0.0, f64::max);
        let rho = AUGMENT * top;
        let c_rho = c + rho * (&g * g.transpose());
        Floating { g, rho, c_rho, motions }
    }

    /// Number of rigid motions.
    pub fn len(&self) -> usize {
        self.g.ncols()
    }

    /// Always false (k ≥ 1).
    pub fn is_empty(&self) -> bool {
        self.g.ncols() == 0
    }

    /// Solve step n (time t) for d, the warm start λ₀ and α₀, and the net load e = Rᵀlⁿ; the
    /// solution carries α in `rigid`.
    pub fn solve(
        &self,
        fr: &Friction,
        (d, lam0, alpha0): (&[f64], &[f64], &[f64]),
        e: &[f64],
        n: usize,
        t: f64,
    ) -> Result<FrictionSolution> {
        let k = self.len();
        let mut alpha = if alpha0.len() == k { alpha0.to_vec() } else { vec![0.0; k] };
        let mut lam = lam0.to_vec();
        let (mut last, mut slow, mut iterations) = (f64::INFINITY, 0, 0);
        let mut r = vec![0.0; k];
        for _ in 0..MAX_OUTER {
            let shift: Vec<f64> = (0..k).map(|j| alpha[j] + self.rho * e[j]).collect();
            let dr: Vec<f64> =
                (0..d.len()).map(|i| d[i] + (0..k).map(|j| self.g[(i, j)] * shift[j]).sum::<f64>()).collect();
            let mut sol = fr.solve_on(&self.c_rho, &dr, &lam, n, t)?;
            iterations += sol.iterations;
            lam = sol.mu.iter().chain(&sol.normal).copied().collect();
            let f = lam.iter().chain(e).fold(0.0f64, |a, v| a.max(v.abs()));
            let mut res = 0.0f64;
            for j in 0..k {
                let gl: f64 = (0..lam.len()).map(|i| self.g[(i, j)] * lam[i]).sum();
                r[j] = e[j] - gl;
                alpha[j] += self.rho * r[j];
                let scale = self.g.column(j).iter().map(|v| v.abs()).sum::<f64>() * f;
                res = res.max(if r[j] == 0.0 { 0.0 } else { r[j].abs() / scale.max(f64::MIN_POSITIVE) });
            }
            if res <= fr.settings.tol {
                sol.rigid = alpha;
                sol.iterations = iterations;
                return Ok(sol);
            }
            slow = if res > 0.5 * last { slow + 1 } else { 0 };
            if slow >= STALLED {
                break;
            }
            last = res;
        }
        Err(self.unbalanced(&r, n, t))
    }

    /// The refusal of a step whose loads no contact force within the bounds balances: the motion along
    /// the residual e − Gᵀλ, with the net force and moment it leaves.
    fn unbalanced(&self, r: &[f64], n: usize, t: f64) -> Error {
        // r_j = (f, M)·m_j for the motions m_j = (a_j, b_j, θ_j): the smallest (f, M) doing that work,
        // w = m z with (mᵀm) z = r, and the motion it pushes along, Σ_j z_j R_j
        let m = &self.motions.m;
        let z = (m.transpose() * m)
            .cholesky()
            .map(|ch| ch.solve(&nalgebra::DVector::from_column_slice(r)))
            .map_or_else(|| r.to_vec(), |z| z.iter().copied().collect());
        let w = m * nalgebra::DVector::from_column_slice(&z);
        Error::Unbalanced {
            step: n,
            time: t,
            motion: self.motions.describe(&z),
            force: [w[0], w[1]],
            moment: w[2],
            centre: self.motions.centre,
        }
    }
}

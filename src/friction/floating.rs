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

use super::{balance, Friction, FrictionSolution};
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

/// A smallest unbalanced load (`balance`) below this fraction of the net load is the diagnosis's own
/// error (its projected gradient iterations reach r* to about this accuracy): the loads are balanced.
const BALANCED: f64 = 1e-3;

/// An eigenvalue of G_IᵀG_I (G_I: G's rows where the force is within its bounds) below this is a rigid
/// motion that nothing holds (G_I has orthonormal columns when every row holds).
const FREE: f64 = 1e-10;

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
                self.determined(fr, &lam, n, t)?;
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
        // the equality stalled: is there a balance at all (`balance`)? If not, the refusal names the
        // motion the smallest unbalanced load pushes along; if so, the iteration failed
        let nm = fr.normal.as_ref();
        let set = balance::Admissible {
            w: &fr.w,
            coulomb: nm.map_or(&[][..], |m| &m.coulomb[..]),
            lo: nm.map_or(&[][..], |m| &m.lo[..]),
        };
        let unbalanced = balance::unbalanced(&self.g, e, &set, &lam);
        let size = e.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if unbalanced.iter().any(|v| v.abs() > BALANCED * size) {
            return Err(self.unbalanced(&unbalanced, n, t));
        }
        let last = if last.is_finite() { last } else { f64::NAN };
        Err(Error::NotConverged {
            step: n,
            time: t,
            solver: "the equilibrium of the rigid motions (method of multipliers)",
            iterations,
            residual: last,
            tol: fr.settings.tol,
        })
    }

    /// The rigid motion must be fixed by the solution: G's rows on the unknowns whose force lies strictly
    /// within its bounds (where Δ = 0 holds as an equation) have rank k. Otherwise α is not unique (a
    /// frictionless body free to slide, say): refused naming the motion nothing holds.
    fn determined(&self, fr: &Friction, lam: &[f64], n: usize, t: f64) -> Result<()> {
        let nc = fr.w.len();
        let nm = fr.normal.as_ref();
        let size = lam.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(f64::MIN_POSITIVE);
        let inside = |i: usize| -> bool {
            let margin = 1e-9 * size;
            if i >= nc {
                let lo = nm.map_or(0.0, |m| m.lo[i - nc]);
                return lam[i] > lo + margin;
            }
            let bound = match nm.and_then(|m| m.coulomb[i]) {
                Some(f) => f * lam[nc + i].abs(),
                None => fr.w[i],
            };
            lam[i].abs() < bound - margin
        };
        let rows: Vec<usize> = (0..lam.len()).filter(|&i| inside(i)).collect();
        let gi = DMatrix::from_fn(rows.len(), self.len(), |a, j| self.g[(rows[a], j)]);
        let eig = nalgebra::SymmetricEigen::new(gi.transpose() * gi);
        let (j, low) =
            eig.eigenvalues.iter().enumerate().fold((0, f64::INFINITY), |a, (j, &v)| if v < a.1 { (j, v) } else { a });
        // G has orthonormal columns: an eigenvalue ≪ 1 is a motion the holding unknowns do not see
        if low > FREE {
            return Ok(());
        }
        let v: Vec<f64> = eig.eigenvectors.column(j).iter().copied().collect();
        Err(Error::Unheld { step: n, time: t, motion: self.motions.describe(&v) })
    }

    /// The refusal of a step whose loads no contact force within the bounds balances: the motion along
    /// the residual e − Gᵀλ, with the net force and moment it leaves.
    fn unbalanced(&self, r: &[f64], n: usize, t: f64) -> Error {
        // r_j = (f, M)·m_j for the motions m_j = (a_j, b_j, θ_j): the smallest (f, M) doing that work,
        // w = m z with (mᵀm) z = r; the motion it pushes along most (per unit of G's norm) is Σ_j r_j R_j
        let m = &self.motions.m;
        let z = (m.transpose() * m)
            .cholesky()
            .map(|ch| ch.solve(&nalgebra::DVector::from_column_slice(r)))
            .map_or_else(|| r.to_vec(), |z| z.iter().copied().collect());
        let w = m * nalgebra::DVector::from_column_slice(&z);
        Error::Unbalanced {
            step: n,
            time: t,
            motion: self.motions.describe(r),
            force: [w[0], w[1]],
            moment: w[2],
            centre: self.motions.centre,
        }
    }
}

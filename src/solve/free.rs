//! The free response of a step: u_f = K⁻¹lⁿ, the displacement the load lⁿ would cause without
//! friction, and its contact trace s_f = Eᵀu_f, each by the cheapest route the run allows:
//!
//! * superposed loads ([`LoadBasis`]): u_f = Σ_j cₙⱼ K⁻¹b_j and s_f from the contact entries alone
//!   (O(rank · n_c) when u is not wanted), no assembly and no solve;
//! * otherwise lⁿ is assembled and, with Γ_C, only the forward half y = L⁻¹Pᵀlⁿ is solved: the factor
//!   orders the contact unknowns last, so s_f = Wᵀy_c with W = L_cc⁻¹ (`condense`), O(n_c²);
//!   without Γ_C, u_f = K⁻¹lⁿ by one pair of triangular solves.
//!
//! After the friction solve, [`FreeResponse::with_friction`] gives uⁿ = K⁻¹(lⁿ − Eμ) = u_f − K⁻¹Eμ: from
//! the forward half, y_c ← y_c − Wμ (since L⁻¹E = [0; W]) and one backward half — so a step costs one
//! pair of triangular solves in all; with superposed loads, u_f − P L⁻ᵀ[0; Wμ] (one backward half,
//! reused while μ repeats). The factor of K lives here: it is the only thing that solves with K during
//! stepping.

use super::condense::{condense, Condensation};
use super::factor::Factor;
use super::superpose::LoadBasis;
use crate::error::Result;
use crate::fem::loads::Loads;
use crate::fem::space::CrSpace;
use nalgebra::DMatrix;
use std::cell::RefCell;

/// u_f and s_f of one step at any time node.
pub struct FreeResponse {
    factor: Factor,
    loads: Loads,
    basis: Option<LoadBasis>,
    n_dofs: usize,
    /// Contact unknowns (empty without Γ_C).
    contact_dofs: Vec<usize>,
    /// W = L_cc⁻¹ (see `condense`; empty without Γ_C).
    w: DMatrix<f64>,
    /// The last μ given to [`FreeResponse::subtract_friction`] and its K⁻¹Eμ: once Γ_C slips (or sticks)
    /// everywhere μ stays the same from step to step, and K⁻¹Eμ is reused instead of recomputed
    /// (keyed on bit-equal μ, so the result does not depend on the cache).
    friction_cache: RefCell<(Vec<f64>, Vec<f64>)>,
}

/// One step's free response. `u` is u_f when formed, else empty (with Γ_C, a wanted u is formed by
/// [`FreeResponse::with_friction`] from the kept forward half).
pub struct Free {
    pub u: Vec<f64>,
    /// s_f = Eᵀu_f (empty without Γ_C).
    pub trace: Vec<f64>,
    /// y = L⁻¹Pᵀlⁿ, when u is wanted and was left half-solved.
    forward: Option<Vec<f64>>,
}

impl FreeResponse {
    /// Condense onto the contact unknowns and superpose the loads of `times` where they span few
    /// patterns. Returns the response and C = EᵀK⁻¹E (`None` without Γ_C).
    pub fn new(
        factor: Factor,
        loads: Loads,
        space: &CrSpace,
        times: &[f64],
    ) -> Result<(FreeResponse, Option<DMatrix<f64>>)> {
        let n = space.n_dofs;
        let contact_dofs: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        let (c, w) = if contact_dofs.is_empty() {
            (None, DMatrix::zeros(0, 0))
        } else {
            let Condensation { c, w } = condense(&contact_dofs, &factor)?;
            (Some(c), w)
        };
        let basis = LoadBasis::build(&loads, times, &factor)?;
        let free = FreeResponse {
            factor,
            loads,
            basis,
            n_dofs: n,
            contact_dofs,
            w,
            friction_cache: RefCell::new((vec![], vec![])),
        };
        Ok((free, c))
    }

    /// The factor of K.
    pub fn factor(&self) -> &Factor {
        &self.factor
    }

    /// True if the loads are superposed from a few patterns (no assembly or solve per step).
    pub fn superposed(&self) -> bool {
        self.basis.is_some()
    }

    /// The load functional.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// u_f and s_f at time node n (time t). `load` receives lⁿ whenever u is wanted (it is scratch
    /// otherwise); u_f is formed when `want_u` with superposed loads, or when there is no Γ_C (then it is
    /// the solution).
    pub fn at(&self, n: usize, t: f64, want_u: bool, load: &mut Vec<f64>) -> Result<Free> {
        let dofs = self.n_dofs;
        let contact = !self.contact_dofs.is_empty();
        let mut u = Vec::new();
        let mut forward = None;
        let trace = match &self.basis {
            Some(b) => {
                if want_u || !contact {
                    b.load(n, dofs, load);
                    b.response(n, dofs, &mut u);
                }
                if contact {
                    b.response_at(n, &self.contact_dofs)
                } else {
                    vec![]
                }
            }
            None => {
                self.loads.assemble(t, load)?;
                if contact {
                    let mut y = load.clone();
                    self.factor.forward_solve(&mut y)?;
                    // s_f = L_cc⁻ᵀ y_c = Wᵀ y_c
                    let yc = &y[dofs - self.contact_dofs.len()..];
                    let trace = (0..yc.len()).map(|j| (j..yc.len()).map(|i| self.w[(i, j)] * yc[i]).sum()).collect();
                    if want_u {
                        forward = Some(y);
                    }
                    trace
                } else {
                    u.extend_from_slice(load);
                    self.factor.solve_in_place(&mut u);
                    vec![]
                }
            }
        };
        Ok(Free { u, trace, forward })
    }

    /// uⁿ = K⁻¹(lⁿ − Eμ) from the step's free response and the friction force μ.
    pub fn with_friction(&self, free: Free, mu: &[f64]) -> Result<Vec<f64>> {
        match free.forward {
            Some(mut y) => {
                // L⁻¹Eμ = [0; Wμ]
                let n0 = self.n_dofs - mu.len();
                for i in 0..mu.len() {
                    y[n0 + i] -= (0..=i).map(|j| self.w[(i, j)] * mu[j]).sum::<f64>();
                }
                self.factor.backward_solve(&mut y)?;
                Ok(y)
            }
            None => {
                let mut u = free.u;
                self.subtract_friction(&mut u, mu)?;
                Ok(u)
            }
        }
    }

    /// u ← u_f − K⁻¹Eμ with K⁻¹Eμ = P L⁻ᵀ[0; Wμ] (one backward half), for a formed u_f (superposed
    /// loads, or given by the caller).
    pub fn subtract_friction(&self, u: &mut [f64], mu: &[f64]) -> Result<()> {
        let n = u.len();
        let mut cache = self.friction_cache.borrow_mut();
        let (last_mu, zmu) = &mut *cache;
        let same = last_mu.len() == mu.len()
            && zmu.len() == n
            && last_mu.iter().zip(mu).all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            zmu.clear();
            zmu.resize(n, 0.0);
            let n0 = n - mu.len();
            for i in 0..mu.len() {
                zmu[n0 + i] = (0..=i).map(|j| self.w[(i, j)] * mu[j]).sum::<f64>();
            }
            self.factor.backward_solve(zmu)?;
            last_mu.clear();
            last_mu.extend_from_slice(mu);
        }
        u.iter_mut().zip(zmu.iter()).for_each(|(ui, a)| *ui -= a);
        Ok(())
    }
}

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
//! stepping. With Γ_C, consecutive steps share their triangular solves in blocks (`blocks`).

mod blocks;

pub use super::block::Block;
use super::cholesky::Factor;
use super::condense::Condensation;
use super::kernel::Kernel;
use super::superpose::LoadBasis;
use crate::error::Result;
use crate::fem::loads::Loads;
use crate::fem::space::CrSpace;
pub use blocks::BLOCK_BYTES;
use nalgebra::DMatrix;
use std::cell::RefCell;
use std::sync::Arc;

/// u_f and s_f of one step at any time node.
pub struct FreeResponse {
    factor: Arc<Factor>,
    loads: Loads,
    basis: Option<LoadBasis>,
    /// Loads on the support that a refused superposition assembled, by node (`LoadBasis::build`): the
    /// steps at those nodes use them (the same values) instead of assembling them again.
    assembled: Vec<(usize, Vec<f64>)>,
    n_dofs: usize,
    /// Contact unknowns (empty without Γ_C).
    contact_dofs: Vec<usize>,
    /// W = L_cc⁻¹ (see `condense`; empty without Γ_C).
    w: DMatrix<f64>,
    /// The last μ given to [`FreeResponse::subtract_friction`] and its K⁻¹Eμ: once Γ_C slips (or sticks)
    /// everywhere μ stays the same from step to step, and K⁻¹Eμ is reused instead of recomputed
    /// (keyed on bit-equal μ, so the result does not depend on the cache).
    friction_cache: RefCell<(Vec<f64>, Vec<f64>)>,
    /// The rigid motions of a floating body (`None`: K is nonsingular). The factor is then K_#'s, and
    /// every solve above is K⁺'s once [`FreeResponse::complete`] has zeroed the pinned unknowns.
    kernel: Option<Kernel>,
}

/// One step's free response. `u` is u_f when formed, else empty (with Γ_C, a wanted u is formed by
/// [`FreeResponse::with_friction`] from the kept forward half).
pub struct Free {
    pub u: Vec<f64>,
    /// s_f = Eᵀu_f (empty without Γ_C).
    pub trace: Vec<f64>,
    /// y = L⁻¹Pᵀlⁿ, when u is wanted and was left half-solved.
    forward: Option<Vec<f64>>,
    /// e = Rᵀlⁿ, the net load on the rigid motions of a floating body (empty otherwise).
    pub net: Vec<f64>,
}

impl FreeResponse {
    /// The free response from the factor, the load superposition (`basis`, when the loads span few
    /// patterns) and the condensation onto the contact unknowns (`None` without Γ_C). Returns the
    /// response and C = EᵀK⁻¹E (`None` without Γ_C).
    pub fn new(
        factor: Arc<Factor>,
        loads: Loads,
        basis: Option<LoadBasis>,
        assembled: Vec<(usize, Vec<f64>)>,
        condensation: Option<Condensation>,
        space: &CrSpace,
        kernel: Option<Kernel>,
    ) -> (FreeResponse, Option<DMatrix<f64>>) {
        let n = space.n_dofs;
        let contact_dofs: Vec<usize> = space.contact_dofs();
        let (c, w) = match condensation {
            Some(Condensation { c, w }) => (Some(c), w),
            None => (None, DMatrix::zeros(0, 0)),
        };
        let free = FreeResponse {
            factor,
            loads,
            basis,
            assembled,
            n_dofs: n,
            contact_dofs,
            w,
            friction_cache: RefCell::new((vec![], vec![])),
            kernel,
        };
        (free, c)
    }

    /// lⁿ (time t) on the loads' support: kept from the superposition's attempt, else assembled.
    fn load_on_support(&self, n: usize, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let Some((_, l)) = self.assembled.iter().find(|(m, _)| *m == n) else {
            return self.loads.assemble_on_support(t, out);
        };
        out.clone_from(l);
        Ok(())
    }

    /// The rigid motions of a floating body (`None`: K is nonsingular).
    pub fn kernel(&self) -> Option<&Kernel> {
        self.kernel.as_ref()
    }

    /// u ← K⁺(lⁿ − Eλ) + Rα from the solve with K_# (no-op without rigid motions).
    pub fn complete(&self, u: &mut [f64], alpha: &[f64]) {
        if let Some(k) = &self.kernel {
            k.complete(u, alpha);
        }
    }

    /// The factor of K (of K_# for a floating body, `kernel`).
    pub fn factor(&self) -> &Factor {
        &self.factor
    }

    /// True if the loads are superposed from a few patterns (no assembly or solve per step).
    pub fn superposed(&self) -> bool {
        self.basis.is_some()
    }

    /// lⁿ = l(tₙ) on every unknown, by the cheapest route: from the superposition's patterns when the
    /// loads are superposed (equal to the assembled load within its span tolerance), else assembled.
    pub fn load_at(&self, n: usize, t: f64, out: &mut Vec<f64>) -> Result<()> {
        match &self.basis {
            Some(b) => {
                b.load(n, self.n_dofs, out);
                Ok(())
            }
            None => self.loads.assemble(t, out),
        }
    }

    /// The load functional.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// s_f = L_cc⁻ᵀ y_c = Wᵀ y_c.
    fn trace_of(&self, yc: &[f64]) -> Vec<f64> {
        (0..yc.len()).map(|j| (j..yc.len()).map(|i| self.w[(i, j)] * yc[i]).sum()).collect()
    }

    /// Wμ (W = L_cc⁻¹ lower triangular), the contact part of L⁻¹Eμ = [0; Wμ].
    fn w_mu(&self, mu: &[f64]) -> Vec<f64> {
        (0..mu.len()).map(|i| (0..=i).map(|j| self.w[(i, j)] * mu[j]).sum::<f64>()).collect()
    }

    /// y_c ← y_c − Wμ.
    fn subtract_w_mu(&self, y: &mut [f64], mu: &[f64]) {
        let n0 = self.n_dofs - mu.len();
        y[n0..].iter_mut().zip(self.w_mu(mu)).for_each(|(y, w)| *y -= w);
    }

    /// u_f and s_f at time node n (time t). `load` receives lⁿ whenever u is wanted (it is scratch
    /// otherwise); u_f is formed when `want_u` with superposed loads, or when there is no Γ_C (then it is
    /// the solution).
    pub fn at(&self, n: usize, t: f64, want_u: bool, load: &mut Vec<f64>) -> Result<Free> {
        let dofs = self.n_dofs;
        let contact = !self.contact_dofs.is_empty();
        let mut u = Vec::new();
        let mut forward = None;
        let mut net = Vec::new();
        let trace = match &self.basis {
            Some(b) => {
                if want_u || !contact {
                    b.load(n, dofs, load);
                    b.response(n, dofs, &mut u);
                }
                if let Some(k) = &self.kernel {
                    net = b.net(n, k);
                }
                if contact {
                    b.response_at(n, &self.contact_dofs)
                } else {
                    vec![]
                }
            }
            None => {
                let mut on_support = Vec::new();
                self.load_on_support(n, t, &mut on_support)?;
                if let Some(k) = &self.kernel {
                    net = k.net(self.loads.support(), &on_support);
                }
                self.loads.expand(&on_support, load);
                if contact {
                    let mut y = load.clone();
                    self.factor.forward_solve(&mut y)?;
                    let trace = self.trace_of(&y[dofs - self.contact_dofs.len()..]);
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
        Ok(Free { u, trace, forward, net })
    }

    /// uⁿ = K⁻¹(lⁿ − Eμ) from the step's free response and the friction force μ.
    pub fn with_friction(&self, free: Free, mu: &[f64]) -> Result<Vec<f64>> {
        match free.forward {
            Some(mut y) => {
                self.subtract_w_mu(&mut y, mu);
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
            zmu[n0..].copy_from_slice(&self.w_mu(mu));
            self.factor.backward_solve(zmu)?;
            last_mu.clear();
            last_mu.extend_from_slice(mu);
        }
        u.iter_mut().zip(zmu.iter()).for_each(|(ui, a)| *ui -= a);
        Ok(())
    }
}

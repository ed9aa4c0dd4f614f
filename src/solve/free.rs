//! The free response of a step: u_f = K⁻¹lⁿ, the displacement the load lⁿ would cause without
//! friction, and its contact trace s_f = Eᵀu_f, each by the cheapest route the run allows:
//!
//! * superposed loads ([`LoadBasis`]): u_f = Σ_j cₙⱼ K⁻¹b_j and s_f from the contact entries alone
//!   (O(rank · n_c) when u is not wanted), no assembly and no solve;
//! * otherwise lⁿ is assembled, and s_f = Zᵀlⁿ when only the trace is wanted and Z = K⁻¹E is kept
//!   (`condense`), else u_f = K⁻¹lⁿ by one pair of triangular solves and s_f read off it.
//!
//! After the friction solve, [`FreeResponse::subtract_friction`] gives uⁿ = u_f − K⁻¹Eμ (from Z, or one
//! more solve). The factor of K lives here: it is the only thing that solves with K during stepping.

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
    /// Z = K⁻¹E, column-major, when kept (see `condense`).
    z: Option<Vec<f64>>,
    /// The last μ given to [`FreeResponse::subtract_friction`] and its K⁻¹Eμ: once Γ_C slips (or sticks)
    /// everywhere μ stays the same from step to step, and K⁻¹Eμ is reused instead of recomputed
    /// (keyed on bit-equal μ, so the result does not depend on the cache).
    friction_cache: RefCell<(Vec<f64>, Vec<f64>)>,
}

/// One step's free response. `u` is empty when it was not wanted (and not needed).
pub struct Free {
    pub u: Vec<f64>,
    /// s_f = Eᵀu_f (empty without Γ_C).
    pub trace: Vec<f64>,
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
        let (c, z) = if contact_dofs.is_empty() {
            (None, None)
        } else {
            let Condensation { c, z } = condense(&contact_dofs, &factor, n)?;
            (Some(c), z)
        };
        let basis = LoadBasis::build(&loads, times, &factor)?;
        let free = FreeResponse {
            factor,
            loads,
            basis,
            n_dofs: n,
            contact_dofs,
            z,
            friction_cache: RefCell::new((vec![], vec![])),
        };
        Ok((free, c))
    }

    /// The factor of K.
    pub fn factor(&self) -> &Factor {
        &self.factor
    }

    /// The load functional.
    pub fn loads(&self) -> &Loads {
        &self.loads
    }

    /// u_f and s_f at time node n (time t). `load` receives lⁿ whenever u_f is formed (it is scratch
    /// otherwise); u_f is formed when `want_u` or when there is no Γ_C (then it is the solution).
    pub fn at(&self, n: usize, t: f64, want_u: bool, load: &mut Vec<f64>) -> Result<Free> {
        let dofs = self.n_dofs;
        let contact = !self.contact_dofs.is_empty();
        let mut u = Vec::new();
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
                match &self.z {
                    Some(z) if contact && !want_u => self.trace_of_solution(z, load),
                    _ => {
                        u.extend_from_slice(load);
                        self.factor.solve_in_place(&mut u);
                        self.contact_dofs.iter().map(|&k| u[k]).collect()
                    }
                }
            }
        };
        Ok(Free { u, trace })
    }

    /// Eᵀ K⁻¹ l = Zᵀ l.
    fn trace_of_solution(&self, z: &[f64], l: &[f64]) -> Vec<f64> {
        let n = l.len();
        (0..self.contact_dofs.len()).map(|j| z[j * n..(j + 1) * n].iter().zip(l).map(|(a, b)| a * b).sum()).collect()
    }

    /// u ← u_f − K⁻¹ E μ, with K⁻¹Eμ = Σ_e μ_e z_e from Z, or one pair of triangular solves without it.
    pub fn subtract_friction(&self, u: &mut [f64], mu: &[f64]) {
        let n = u.len();
        let mut cache = self.friction_cache.borrow_mut();
        let (last_mu, zmu) = &mut *cache;
        let same = last_mu.len() == mu.len()
            && zmu.len() == n
            && last_mu.iter().zip(mu).all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            zmu.clear();
            zmu.resize(n, 0.0);
            match &self.z {
                Some(z) => {
                    for (j, &m) in mu.iter().enumerate() {
                        if m != 0.0 {
                            let col = &z[j * n..(j + 1) * n];
                            zmu.iter_mut().zip(col).for_each(|(a, zi)| *a += m * zi);
                        }
                    }
                }
                None => {
                    for (j, &m) in mu.iter().enumerate() {
                        zmu[self.contact_dofs[j]] = m;
                    }
                    self.factor.solve_in_place(zmu);
                }
            }
            last_mu.clear();
            last_mu.extend_from_slice(mu);
        }
        u.iter_mut().zip(zmu.iter()).for_each(|(ui, a)| *ui -= a);
    }
}

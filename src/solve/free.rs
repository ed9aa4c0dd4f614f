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
//!
//! Blocks of steps ([`Block`]): the loads of all time nodes are known in advance, and neither the
//! forward half yⁿ = L⁻¹Pᵀlⁿ nor the trace s_f = Wᵀyⁿ_c depends on the friction force. So when every
//! step assembles and solves, B consecutive steps share one forward solve with B right-hand sides
//! ([`FreeResponse::forward_block`]), the B friction problems are solved in turn, and their
//! uⁿ = P L⁻ᵀ(yⁿ − [0; Wμⁿ]) come from one backward solve with B right-hand sides
//! ([`FreeResponse::finish_block`]). A single-vector supernodal solve is memory-bound (it streams all of
//! L for 2 flops an entry); with B columns L is read once per block and the work becomes dense
//! matrix products. Blocks are aligned to the step numbers (block q holds steps qB+1, …, qB+B in
//! columns 0, …, B−1) and solved with B columns, the run's last block with as many as it has steps
//! (N − qB when that is fewer: a 4-step run solves 4 columns, not 16); steps before a resumed run's first
//! are zero columns. The widths are fixed by the step numbers, and faer computes each column
//! independently of the others' values (though not of the width), so every step gets the same
//! arithmetic whether a run starts at step 0 or resumes, and results do not depend on where a run
//! started.

pub use super::block::Block;
use super::cholesky::Factor;
use super::condense::Condensation;
use super::kernel::Kernel;
use super::superpose::LoadBasis;
use crate::error::{Error, Result};
use crate::fem::loads::Loads;
use crate::fem::space::CrSpace;
use nalgebra::DMatrix;
use std::cell::RefCell;
use std::ops::RangeInclusive;
use std::sync::Arc;

/// Right-hand sides of a block: at most this many values (B·n ≤ 2^24, 128 MiB per buffer).
const BLOCK_VALUES: usize = 1 << 24;
/// Steps in a block at most (at 196,608 unknowns a solve pair costs 61 ms for one column, 13 ms a
/// column for 8, 9 ms for 16 and 7.6 ms for 32).
const MAX_BLOCK: usize = 16;
/// Bytes of a block's two buffers (right-hand sides and solutions) at most.
pub const BLOCK_BYTES: u64 = 2 * 8 * BLOCK_VALUES as u64;

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

    /// e = Rᵀlⁿ of step n in the block (empty without rigid motions).
    pub fn block_net(&self, block: &Block, n: usize) -> Vec<f64> {
        let Some(k) = &self.kernel else {
            return vec![];
        };
        match &self.basis {
            Some(b) => b.net(n, k),
            None => k.net_full(&block.loads[block.col(n)]),
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

    /// Steps per block with Γ_C (see [`Block`]), else 0: without Γ_C steps are solved one by one.
    pub fn block_size(&self) -> usize {
        if self.contact_dofs.is_empty() {
            return 0;
        }
        (BLOCK_VALUES / self.n_dofs.max(1)).clamp(1, MAX_BLOCK)
    }

    /// An empty block for [`FreeResponse::forward_block`].
    pub fn new_block(&self) -> Block {
        let (cols, n) = (self.block_size().max(1), self.n_dofs);
        let (loads, y) = (vec![0.0; cols * n], vec![0.0; cols * n]);
        Block { first: 0, cols, width: cols, n, loads, y, friction: (vec![], vec![]) }
    }

    /// Assemble lⁿ and solve the forward halves yⁿ for the steps `steps` that lie in the aligned block
    /// holding the first of them (its other columns are zero); with superposed loads nothing is done
    /// here. Returns the last step of the block in `steps` and, if the load of the step after it
    /// failed, that error: the caller completes the steps before it first, as a run step by step would.
    pub fn forward_block(
        &self,
        steps: RangeInclusive<usize>,
        times: &[f64],
        block: &mut Block,
    ) -> Result<(usize, Option<Error>)> {
        let b = block.cols;
        block.first = (steps.start().max(&1) - 1) / b * b + 1;
        block.width = b.min((steps.end() + 1).saturating_sub(block.first)).max(1);
        if self.basis.is_some() {
            return Ok(((block.first + b - 1).min(*steps.end()), None));
        }
        let w = block.width * block.n;
        block.loads[..w].iter_mut().for_each(|v| *v = 0.0);
        let mut on_support = Vec::new();
        let steps: Vec<usize> = steps.filter(|&n| block.holds(n)).collect();
        let mut last = steps.first().map_or(0, |&n| n - 1);
        let mut failed = None;
        for n in steps {
            if let Err(e) = self.load_on_support(n, times[n], &mut on_support) {
                failed = Some(e);
                break;
            }
            let range = block.col(n);
            let col = &mut block.loads[range];
            for (&k, &v) in self.loads.support().iter().zip(&on_support) {
                col[k] = v;
            }
            last = n;
        }
        self.factor.permute_in(&block.loads[..w], &mut block.y[..w]);
        self.factor.forward_block(&mut block.y[..w], block.width)?;
        Ok((last, failed))
    }

    /// s_f of a step in the block: Wᵀyⁿ_c, or from the superposed responses.
    pub fn block_trace(&self, block: &Block, n: usize) -> Vec<f64> {
        if let Some(b) = &self.basis {
            return b.response_at(n, &self.contact_dofs);
        }
        let y = &block.y[block.col(n)];
        self.trace_of(&y[self.n_dofs - self.contact_dofs.len()..])
    }

    /// s_f = L_cc⁻ᵀ y_c = Wᵀ y_c.
    fn trace_of(&self, yc: &[f64]) -> Vec<f64> {
        (0..yc.len()).map(|j| (j..yc.len()).map(|i| self.w[(i, j)] * yc[i]).sum()).collect()
    }

    /// uⁿ = P L⁻ᵀ(yⁿ − [0; Wμⁿ]) for the steps and friction forces `mus` of the block, by one backward
    /// solve; the block's forward halves are used up. With superposed loads uⁿ = u_f − P L⁻ᵀ[0; Wμⁿ]
    /// (one backward solve for the μⁿ that differ from the last one solved for) and lⁿ is formed for
    /// [`Block::load`].
    pub fn finish_block(&self, block: &mut Block, mus: &[(usize, &[f64])]) -> Result<Vec<Vec<f64>>> {
        if mus.is_empty() {
            return Ok(vec![]);
        }
        if let Some(b) = &self.basis {
            return self.finish_superposed(b, block, mus);
        }
        for &(n, mu) in mus {
            let range = block.col(n);
            self.subtract_w_mu(&mut block.y[range], mu);
        }
        let w = block.width * block.n;
        self.factor.backward_block(&mut block.y[..w], block.width)?;
        let mut u = vec![0.0; self.n_dofs];
        Ok(mus
            .iter()
            .map(|&(n, _)| {
                self.factor.permute_out(&block.y[block.col(n)], &mut u);
                u.clone()
            })
            .collect())
    }

    fn finish_superposed(&self, b: &LoadBasis, block: &mut Block, mus: &[(usize, &[f64])]) -> Result<Vec<Vec<f64>>> {
        let dofs = self.n_dofs;
        let (old_mu, old_z) = std::mem::take(&mut block.friction);
        let same = |mu: &[f64]| {
            old_z.len() == dofs
                && mu.len() == old_mu.len()
                && mu.iter().zip(&old_mu).all(|(x, y)| x.to_bits() == y.to_bits())
        };
        let solve: Vec<bool> = mus.iter().map(|&(_, mu)| !same(mu)).collect();
        if solve.iter().any(|&s| s) {
            let w = block.width * block.n;
            block.y[..w].iter_mut().for_each(|v| *v = 0.0);
            let n0 = dofs - self.contact_dofs.len();
            for (&(n, mu), _) in mus.iter().zip(&solve).filter(|(_, &s)| s) {
                let range = block.col(n);
                let y = &mut block.y[range];
                y[n0..].copy_from_slice(&self.w_mu(mu));
            }
            self.factor.backward_block(&mut block.y[..w], block.width)?;
        }
        let (mut z, mut l) = (vec![0.0; dofs], Vec::new());
        let mut last = None;
        let mut out = Vec::with_capacity(mus.len());
        for (&(n, _), &s) in mus.iter().zip(&solve) {
            let mut u = Vec::new();
            b.response(n, dofs, &mut u);
            let kinv_e_mu = if s {
                // K⁻¹Eμ = P L⁻ᵀ[0; Wμ]
                self.factor.permute_out(&block.y[block.col(n)], &mut z);
                last = Some(n);
                &z
            } else {
                &old_z
            };
            u.iter_mut().zip(kinv_e_mu).for_each(|(ui, a)| *ui -= a);
            b.load(n, dofs, &mut l);
            let range = block.col(n);
            block.loads[range].copy_from_slice(&l);
            out.push(u);
        }
        block.friction = match last {
            Some(n) => {
                let mu = mus.iter().find(|m| m.0 == n).map_or(vec![], |m| m.1.to_vec());
                self.factor.permute_out(&block.y[block.col(n)], &mut z);
                (mu, z)
            }
            None => (old_mu, old_z),
        };
        Ok(out)
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

//! The free response by blocks of steps ([`Block`]): the loads of all time nodes are known in advance,
//! and neither the forward half yⁿ = L⁻¹Pᵀlⁿ nor the trace s_f = Wᵀyⁿ_c depends on the friction
//! force. So when every step assembles and solves, B consecutive steps share one forward solve with B right-hand sides
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

use super::{Block, FreeResponse};
use crate::error::{Error, Result};
use crate::solve::superpose::LoadBasis;
use std::ops::RangeInclusive;

/// Right-hand sides of a block: at most this many values (B·n ≤ 2^24, 128 MiB per buffer).
const BLOCK_VALUES: usize = 1 << 24;
/// Steps in a block at most (at 196,608 unknowns a solve pair costs 61 ms for one column, 13 ms a
/// column for 8, 9 ms for 16 and 7.6 ms for 32).
const MAX_BLOCK: usize = 16;
/// Bytes of a block's two buffers (right-hand sides and solutions) at most.
pub const BLOCK_BYTES: u64 = 2 * 8 * BLOCK_VALUES as u64;

impl FreeResponse {
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
}

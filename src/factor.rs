//! Factorise once, solve many times: the sparse Cholesky factor K = L Lᵀ of the stiffness (faer, AMD
//! ordering), kept for the whole run. Every step and every friction iteration only performs the pair of
//! triangular solves L Lᵀ x = b, with a scratch buffer allocated once. Sequential: the per-step solves
//! of a 2D problem are too small to profit from threads, and sequential kernels keep runs bit-identical.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SparseColMat;
use faer::{Conj, MatMut, Par, Side};
use std::cell::RefCell;

/// The Cholesky factor of an SPD sparse matrix.
pub struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Vec<f64>,
    scratch: RefCell<MemBuffer>,
    n: usize,
}

impl Factor {
    /// Factorise the SPD matrix `k` (lower triangle read). `simplicial` forces the simplicial kernel,
    /// otherwise faer chooses (supernodal for larger fill).
    pub fn new(k: &SparseColMat<usize, f64>, simplicial: bool) -> Result<Factor> {
        let n = k.nrows();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: if simplicial {
                SupernodalThreshold::FORCE_SIMPLICIAL
            } else {
                SupernodalThreshold::AUTO
            },
            ..Default::default()
        };
        let symbolic = factorize_symbolic_cholesky(k.symbolic(), Side::Lower, SymmetricOrdering::Amd, params)
            .map_err(|e| Error::Linear(format!("symbolic Cholesky failed: {e:?}")))?;
        let mut values = vec![0.0; symbolic.len_val()];
        let mut buf = MemBuffer::try_new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()))
            .map_err(|_| Error::Linear("out of memory for the Cholesky factorisation".into()))?;
        symbolic
            .factorize_numeric_llt(&mut values, k.as_ref(), Side::Lower, Default::default(), Par::Seq, MemStack::new(&mut buf), Default::default())
            .map_err(|e| {
                Error::Linear(format!(
                    "the stiffness matrix is not positive definite ({e:?}): are rigid motions fixed by a Dirichlet part?"
                ))
            })?;
        let scratch = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|_| Error::Linear("out of memory for the solve scratch".into()))?;
        Ok(Factor { symbolic, values, scratch: RefCell::new(scratch), n })
    }

    /// Estimate of the 2-norm condition number λ_max/λ_min of K: `iters` steps of power iteration on K
    /// (matrix products) and of inverse iteration (solves with the factor), from a fixed start vector so
    /// the estimate is deterministic. Both are lower bounds that converge from below; the huge gaps of a
    /// nearly singular K show up within a few iterations.
    pub fn condition_estimate(&self, k: &SparseColMat<usize, f64>, iters: usize) -> f64 {
        let n = self.n;
        if n == 0 {
            return 1.0;
        }
        let start: Vec<f64> = (0..n).map(|i| 1.0 + ((i * 7919) % 104729) as f64 / 104729.0).collect();
        let normalise = |v: &mut Vec<f64>| {
            let s = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            v.iter_mut().for_each(|x| *x /= s);
            s
        };
        let (mut hi, mut lo_inv) = (0.0, 0.0);
        let mut v = start.clone();
        normalise(&mut v);
        let mut w = vec![0.0; n];
        for _ in 0..iters {
            crate::assemble::matvec(k, &v, &mut w);
            std::mem::swap(&mut v, &mut w);
            hi = normalise(&mut v);
        }
        let mut v = start;
        normalise(&mut v);
        for _ in 0..iters {
            self.solve_in_place(&mut v);
            lo_inv = normalise(&mut v);
        }
        hi * lo_inv
    }

    /// Number of nonzeros of L.
    pub fn nnz(&self) -> usize {
        self.values.len()
    }

    /// x ← K⁻¹ x for one vector.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let llt = LltRef::new(&self.symbolic, &self.values);
        let mut buf = self.scratch.borrow_mut();
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, self.n, 1),
            Par::Seq,
            MemStack::new(&mut buf),
        );
    }

    /// X ← K⁻¹ X for a block of right-hand sides.
    pub fn solve_many(&self, x: MatMut<'_, f64>) {
        let llt = LltRef::new(&self.symbolic, &self.values);
        let mut buf = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(x.ncols(), Par::Seq));
        llt.solve_in_place_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut buf));
    }
}

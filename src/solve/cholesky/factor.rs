//! Factorise once, solve many times: the sparse Cholesky factor K = P L Lᵀ Pᵀ of the stiffness (faer,
//! supernodal), kept for the whole run. Every step and every friction iteration only performs the pair of
//! triangular solves L Lᵀ x = b, with a scratch buffer allocated once. The numeric factorisation and the
//! solves with several right-hand sides use the thread count in force (`crate::threads`) in faer's dense
//! kernels; single-vector solves are sequential (see `solve_par`). Neither changes a bit with the count.
//!
//! Fill-reducing ordering P: see [`super::ordering`]; the symbolic half: [`super::symbolic`].
//!
//! Unknowns ordered last ([`Factor::with_last`], the contact unknowns): with K's permuted form
//! [K_oo K_ol; K_lo K_ll] = L Lᵀ, the trailing block of L satisfies L_ll L_llᵀ = K_ll − K_lo K_oo⁻¹ K_ol,
//! the Schur complement, whose inverse is the block (K⁻¹)_ll. So the condensed operator comes from the
//! factor without any solve ([`Factor::last_block`]), and since L⁻¹E = [0; L_ll⁻¹] (L lower
//! triangular) a step can split its solve into the halves [`Factor::forward_solve`] and
//! [`Factor::backward_solve`] and add the friction force in between (`solve::free`). Moving a few
//! boundary unknowns to the end of a fill-reducing ordering changes the fill little (they act as one
//! more separator). The supernodal kernel is always used: it exposes the triangular halves and the
//! trailing block.

use super::ordering::{Graph, METIS_MIN_SIZE};
use super::pages::Pages;
use super::symbolic::{fill_order, Symbolic};
use super::symbolic::{lower_nnz, numeric_scratch};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::reborrow::Reborrow;
use faer::sparse::linalg::cholesky::supernodal::{
    factorize_supernodal_numeric_llt, SupernodalLltRef, SymbolicSupernodalCholesky,
};
use faer::sparse::utils::permute_self_adjoint_to_unsorted;
use faer::sparse::SparseColMat;
use faer::{Conj, MatMut, Par, Side};
use nalgebra::DMatrix;
use std::sync::Mutex;

/// The Cholesky factor of an SPD sparse matrix.
pub struct Factor {
    symbolic: SymbolicSupernodalCholesky<usize>,
    values: Pages,
    /// Solve scratch, sized for this many right-hand sides.
    /// (A mutex, not a cell, so the factor can be shared with the condition estimate's thread.)
    scratch: Mutex<(usize, MemBuffer)>,
    n: usize,
    /// The unknowns ordered last, in this order (see [`Factor::with_last`]).
    last: Vec<usize>,
    /// The fill-reducing permutation: position → unknown.
    fwd: Vec<usize>,
    /// How that permutation was made ([`Symbolic::ordered_by`]).
    ordering: &'static str,
    /// The threads that computed it (one where the scratch of several did not fit: [`Factor::threads`]).
    threads: usize,
}

impl Factor {
    /// Factorise the SPD matrix `k` (lower triangle read) with faer's supernodal kernel.
    pub fn new(k: &SparseColMat<usize, f64>) -> Result<Factor> {
        Factor::with_last(k, &[])
    }

    /// As [`Factor::new`], with the distinct unknowns `last` ordered last, in the given order.
    pub fn with_last(k: &SparseColMat<usize, f64>, last: &[usize]) -> Result<Factor> {
        let singletons: Vec<usize> = (0..=k.nrows()).collect();
        Factor::with_groups(k, last, &singletons)
    }

    /// As [`Factor::with_last`], with the fill-reducing ordering computed on the graph whose vertices are
    /// the groups of consecutive unknowns `first[g]..first[g + 1]` (`first` increasing from 0 to n; the
    /// two components of an edge's displacement, `CrSpace::unknown_groups`): see [`super::ordering`].
    pub fn with_groups(k: &SparseColMat<usize, f64>, last: &[usize], first: &[usize]) -> Result<Factor> {
        let n = k.nrows();
        if first.first() != Some(&0) || first.last() != Some(&n) || first.windows(2).any(|w| w[0] >= w[1]) {
            return Err(Error::Linear(
                "internal: unknown groups must increase from 0 to the number of unknowns".into(),
            ));
        }
        Factor::with_order(k, last, fill_order(&Graph::of_matrix(k, first), n >= METIS_MIN_SIZE)?)
    }

    /// As [`Factor::with_last`], with the fill-reducing ordering `base` (position → unknown, a
    /// permutation; from [`fill_order`]): the unknowns `last` are moved to its end.
    pub fn with_order(k: &SparseColMat<usize, f64>, last: &[usize], base: Vec<usize>) -> Result<Factor> {
        Factor::numeric(Symbolic::new(k.symbolic(), last, base)?, k)
    }

    /// The numeric factorisation of `k`, whose pattern is the one `symbolic` was computed from.
    pub fn numeric(symbolic: Symbolic, k: &SparseColMat<usize, f64>) -> Result<Factor> {
        Factor::numeric_beside(symbolic, k, || ()).0
    }

    /// As [`Factor::numeric`], with faer's parallelism `par` instead of the thread count in force
    /// ([`crate::threads::par`]).
    pub fn numeric_with(symbolic: Symbolic, k: &SparseColMat<usize, f64>, par: Par) -> Result<Factor> {
        Factor::numeric_par(par, symbolic, k, || (), crate::machine::available_memory()).0
    }

    /// As [`Factor::numeric`], running `beside` on the second thread that maps the factor's pages
    /// (solve::cholesky::pages) once they are mapped: the caller's work that needs neither the factor nor the
    /// whole of a core. Its result is returned whether the factorisation succeeds or not (`None` if
    /// the factorisation could not start).
    pub fn numeric_beside<R: Send>(
        symbolic: Symbolic,
        k: &SparseColMat<usize, f64>,
        beside: impl FnOnce() -> R + Send,
    ) -> (Result<Factor>, Option<R>) {
        Factor::numeric_par(symbolic.par_in_force(), symbolic, k, beside, crate::machine::available_memory())
    }

    /// The numeric factorisation with the parallelism `par`, or on one thread when `par`'s scratch does not
    /// fit in `have` bytes, refused when neither fits ([`Symbolic::par_that_fits`]).
    pub(super) fn numeric_par<R: Send>(
        par: Par,
        symbolic: Symbolic,
        k: &SparseColMat<usize, f64>,
        beside: impl FnOnce() -> R + Send,
        have: Option<u64>,
    ) -> (Result<Factor>, Option<R>) {
        let n = k.nrows();
        // K kept as its lower triangle (a run's) has as many entries as the pattern's; both triangles stored, more
        let same = k.compute_nnz() == symbolic.pattern_nnz || lower_nnz(k.symbolic()) == symbolic.pattern_nnz;
        if symbolic.symbolic.nrows() != n || !same {
            let e = "internal: the matrix does not have the pattern of its symbolic factorisation";
            return (Err(Error::Linear(e.into())), None);
        }
        let par = match symbolic.par_that_fits((0, 0), par, have) {
            Ok(p) => p,
            Err(e) => return (Err(e), None),
        };
        let Symbolic { symbolic, fwd, inv, last, pattern_nnz, ordering, .. } = symbolic;
        let oom = || Error::Linear("out of memory for the Cholesky factorisation".into());
        let scratch = numeric_scratch(&symbolic, pattern_nnz, par);
        let Some(mut values) = Pages::zeroed(symbolic.len_val()) else { return (Err(oom()), None) };
        let Ok(mut buf) = MemBuffer::try_new(scratch) else {
            return (Err(oom()), None);
        };
        // the factor's pages are mapped on a second thread while this one computes (solve::cholesky::pages)
        let range = values.range();
        let started = std::thread::scope(|s| {
            let r = crate::threads::scoped(s, "mapping the factor's pages", move || {
                Pages::populate(range);
                beside()
            })?;
            let stack = MemStack::new(&mut buf);
            let numeric = numeric_llt(&symbolic, &mut values, (k, pattern_nnz), (&fwd, &inv), par, stack);
            Ok((numeric, r.join().unwrap_or_else(|e| std::panic::resume_unwind(e))))
        });
        let (numeric, r) = match started {
            Ok(done) => done,
            Err(e) => return (Err(e), None),
        };
        let threads = super::subtrees::threads_of(par, n).unwrap_or(1);
        let factor = Factor::finish(symbolic, values, numeric, n, last, fwd).map(|f| Factor { ordering, threads, ..f });
        (factor, Some(r))
    }

    fn finish(
        symbolic: SymbolicSupernodalCholesky<usize>,
        values: Pages,
        numeric: std::result::Result<(), faer::linalg::solvers::LltError>,
        n: usize,
        last: Vec<usize>,
        fwd: Vec<usize>,
    ) -> Result<Factor> {
        numeric.map_err(|e| {
            Error::Linear(format!(
                "the stiffness matrix is not positive definite ({e:?}): are rigid motions fixed by a Dirichlet part?"
            ))
        })?;
        let scratch = MemBuffer::try_new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|_| Error::Linear("out of memory for the solve scratch".into()))?;
        Ok(Factor { symbolic, values, scratch: Mutex::new((1, scratch)), n, last, fwd, ordering: "given", threads: 1 })
    }

    /// How the fill-reducing ordering was made (AMD, nested dissection by coordinates, METIS).
    pub fn ordering(&self) -> &'static str {
        self.ordering
    }

    /// The threads of the numeric factorisation: the thread count in force, or one where the factor is
    /// small or the scratch of several threads did not fit in the memory available (the factor is the
    /// same bit for bit).
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Entries of L kept (supernodal blocks included).
    pub fn len_val(&self) -> usize {
        self.values.len()
    }

    /// Floating-point operations of the numeric factorisation, Σ_j c_j² over the columns j of L with
    /// c_j entries each (diagonal included; the count CHOLMOD reports), and the entries of L without
    /// the supernodal blocks' upper triangles, Σ_j c_j.
    pub fn flops_and_entries(&self) -> (f64, f64) {
        super::symbolic::flops_and_entries(&self.symbolic)
    }

    /// The unknowns ordered last (see [`Factor::with_last`]).
    pub fn last(&self) -> &[usize] {
        &self.last
    }

    fn supernodal(&self) -> Option<SupernodalLltRef<'_, usize, f64>> {
        Some(SupernodalLltRef::new(&self.symbolic, &self.values))
    }

    /// L_ll, the trailing m × m block of L for the m unknowns ordered last (rows and columns in the
    /// order of [`Factor::last`]), lower triangular: L_ll L_llᵀ = ((K⁻¹)_ll)⁻¹.
    pub fn last_block(&self) -> Result<DMatrix<f64>> {
        let m = self.last.len();
        let n0 = self.n - m;
        let llt = self.supernodal().ok_or_else(|| Error::Linear("the factor is not supernodal".into()))?;
        let mut l = DMatrix::zeros(m, m);
        for s in (0..llt.symbolic().n_supernodes()).rev() {
            let sn = llt.supernode(s);
            let (start, val, pattern) = (sn.start(), sn.val(), sn.pattern());
            let size = val.ncols();
            if start + size <= n0 {
                break;
            }
            for jj in 0..size {
                let g = start + jj;
                if g < n0 {
                    continue;
                }
                for ii in jj..size {
                    l[(start + ii - n0, g - n0)] = val[(ii, jj)];
                }
                for (p, &r) in pattern.iter().enumerate() {
                    l[(r - n0, g - n0)] = val[(size + p, jj)];
                }
            }
        }
        Ok(l)
    }

    /// x ← L⁻¹ Pᵀx: the forward half of a solve, the result in the factor's (permuted) order, where
    /// the unknowns ordered last occupy the last positions.
    pub fn forward_solve(&self, x: &mut [f64]) -> Result<()> {
        let mut y = vec![0.0; self.n];
        self.permute_in(x, &mut y);
        self.forward_block(&mut y, 1)?;
        x.copy_from_slice(&y);
        Ok(())
    }

    /// y ← P L⁻ᵀ y: the backward half of a solve, from the factor's order to the unknowns' order.
    pub fn backward_solve(&self, y: &mut [f64]) -> Result<()> {
        self.backward_block(y, 1)?;
        let mut x = vec![0.0; self.n];
        self.permute_out(y, &mut x);
        y.copy_from_slice(&x);
        Ok(())
    }

    /// y ← Pᵀx, column by column (both column-major with n rows): into the factor's order.
    pub fn permute_in(&self, x: &[f64], y: &mut [f64]) {
        if self.n == 0 {
            return;
        }
        for (yc, xc) in y.chunks_exact_mut(self.n).zip(x.chunks_exact(self.n)) {
            yc.iter_mut().zip(&self.fwd).for_each(|(yi, &old)| *yi = xc[old]);
        }
    }

    /// x ← P y, column by column: from the factor's order back to the unknowns' order.
    pub fn permute_out(&self, y: &[f64], x: &mut [f64]) {
        if self.n == 0 {
            return;
        }
        for (xc, yc) in x.chunks_exact_mut(self.n).zip(y.chunks_exact(self.n)) {
            yc.iter().zip(&self.fwd).for_each(|(&yi, &old)| xc[old] = yi);
        }
    }

    /// Y ← L⁻¹Y for the `cols` columns of Y (column-major, n rows, in the factor's order): one pass
    /// over L for all columns, each column computed independently of the others.
    pub fn forward_block(&self, y: &mut [f64], cols: usize) -> Result<()> {
        self.block_half(y, cols, true)
    }

    /// Y ← L⁻ᵀY for the `cols` columns of Y (in the factor's order), as [`Factor::forward_block`].
    pub fn backward_block(&self, y: &mut [f64], cols: usize) -> Result<()> {
        self.block_half(y, cols, false)
    }

    fn block_half(&self, y: &mut [f64], cols: usize, forward: bool) -> Result<()> {
        let llt = self.supernodal().ok_or_else(|| Error::Linear("the factor is not supernodal".into()))?;
        if y.len() != self.n * cols {
            return Err(Error::Linear(format!("internal: a block of {} values for {cols} columns", y.len())));
        }
        let mut scratch = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        let par = solve_par(cols);
        if scratch.0 < cols {
            scratch.1 = MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(cols, par))
                .map_err(|_| Error::Linear("out of memory for the solve scratch".into()))?;
            scratch.0 = cols;
        }
        let (y, stack) = (MatMut::from_column_major_slice_mut(y, self.n, cols), MemStack::new(&mut scratch.1));
        if forward {
            llt.l_solve_with_conj(Conj::No, y, par, stack);
        } else {
            llt.l_transpose_solve_with_conj(Conj::No, y, par, stack);
        }
        Ok(())
    }

    /// x ← K⁻¹ x for one vector (with the factor's own scratch).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let mut scratch = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        self.solve_with(x, 1, MemStack::new(&mut scratch.1));
    }

    /// X ← K⁻¹ X for the `cols` columns of X (column-major, n rows), with a scratch of its own: it may
    /// run beside the factor's other users (the condition estimate's thread).
    pub fn solve_many(&self, x: &mut [f64], cols: usize) {
        let mut buf = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(cols, solve_par(cols)));
        self.solve_with(x, cols, MemStack::new(&mut buf));
    }

    /// Pᵀ, faer's supernodal solve L Lᵀ y = Pᵀx, then P.
    fn solve_with(&self, x: &mut [f64], cols: usize, stack: &mut MemStack) {
        let mut y = vec![0.0; x.len()];
        self.permute_in(x, &mut y);
        let llt = SupernodalLltRef::new(&self.symbolic, &self.values);
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(&mut y, self.n, cols),
            solve_par(cols),
            stack,
        );
        self.permute_out(&y, x);
    }
}

/// The parallelism of a solve with `cols` right-hand sides: the thread count in force for several (faer's
/// dense products then split by output blocks, each column as the sequential kernel computes it), and
/// sequential for one, whose parallel products would split sums (and change their rounding) for a
/// memory-bound kernel that gains little.
fn solve_par(cols: usize) -> Par {
    if cols > 1 {
        crate::threads::par()
    } else {
        Par::Seq
    }
}

/// L's values for K = P L Lᵀ Pᵀ (K's lower triangle: `nnz` entries): that triangle permuted to P K Pᵀ's (as faer's
/// `SymbolicCholesky::factorize_numeric_llt` does it, so the factor is the same bit for bit), then
/// faer's supernodal kernel, sequential, or with several threads its computation by subtrees
/// ([`super::subtrees`]: the same factor bit for bit).
fn numeric_llt(
    symbolic: &SymbolicSupernodalCholesky<usize>,
    values: &mut [f64],
    (k, nnz): (&SparseColMat<usize, f64>, usize),
    (fwd, inv): (&[usize], &[usize]),
    par: Par,
    stack: &mut MemStack,
) -> std::result::Result<(), faer::linalg::solvers::LltError> {
    let n = k.nrows();
    let (mut new_val, stack) = stack.make_with(nnz, |_| 0.0f64);
    let (mut new_col_ptr, stack) = stack.make_with(n + 1, |_| 0usize);
    let (mut new_row_idx, stack) = stack.make_with(nnz, |_| 0usize);
    let perm = PermRef::new_checked(fwd, inv, n);
    let a = permute_self_adjoint_to_unsorted(
        &mut new_val,
        &mut new_col_ptr,
        &mut new_row_idx,
        k.as_ref(),
        perm,
        Side::Lower,
        Side::Lower,
        stack,
    );
    match super::subtrees::threads_of(par, n) {
        Some(threads) => {
            let (mut maps, _) = stack.make_with(super::subtrees::maps_len(n, threads), |_| u32::MAX);
            super::subtrees::factorize(values, a.rb(), symbolic, (threads, &mut maps))
        }
        None => factorize_supernodal_numeric_llt(
            values,
            a.rb(),
            Default::default(),
            symbolic,
            par,
            stack,
            Default::default(),
        )
        .map(|_| ()),
    }
}

#[cfg(test)]
mod tests;

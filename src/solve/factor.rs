//! Factorise once, solve many times: the sparse Cholesky factor K = P L Lᵀ Pᵀ of the stiffness (faer,
//! supernodal), kept for the whole run. Every step and every friction iteration only performs the pair of
//! triangular solves L Lᵀ x = b, with a scratch buffer allocated once. Sequential: the per-step solves
//! of a 2D problem are too small to profit from threads, and sequential kernels keep runs bit-identical.
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

use super::ordering::{Graph, ND_MIN_SIZE};
use super::pages::Pages;
pub use super::symbolic::{fill_order, fill_order_at, Symbolic};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, SymbolicCholeskyRaw};
use faer::sparse::SparseColMat;
use faer::{Conj, MatMut, Par, Side};
use nalgebra::DMatrix;
use std::sync::Mutex;

/// The Cholesky factor of an SPD sparse matrix.
pub struct Factor {
    symbolic: SymbolicCholesky<usize>,
    values: Pages,
    /// Solve scratch, sized for this many right-hand sides.
    /// (A mutex, not a cell, so the factor can be shared with the condition estimate's thread.)
    scratch: Mutex<(usize, MemBuffer)>,
    n: usize,
    /// The unknowns ordered last, in this order (see [`Factor::with_last`]).
    last: Vec<usize>,
    /// The fill-reducing permutation: position → unknown.
    fwd: Vec<usize>,
}

impl Factor {
    /// Factorise the SPD matrix `k` (lower triangle read); faer chooses the simplicial or supernodal
    /// kernel (supernodal for larger fill).
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
        Factor::with_order(k, last, fill_order(&Graph::of_matrix(k, first), n >= ND_MIN_SIZE)?)
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

    /// As [`Factor::numeric`], running `beside` on the second thread that maps the factor's pages
    /// (solve::pages) once they are mapped: the caller's work that needs neither the factor nor the
    /// whole of a core. Its result is returned whether the factorisation succeeds or not (`None` if
    /// the factorisation could not start).
    pub fn numeric_beside<R: Send>(
        symbolic: Symbolic,
        k: &SparseColMat<usize, f64>,
        beside: impl FnOnce() -> R + Send,
    ) -> (Result<Factor>, Option<R>) {
        let Symbolic { symbolic, fwd, last, pattern_nnz } = symbolic;
        let n = k.nrows();
        if symbolic.nrows() != n || k.compute_nnz() != pattern_nnz {
            let e = "internal: the matrix does not have the pattern of its symbolic factorisation";
            return (Err(Error::Linear(e.into())), None);
        }
        let oom = || Error::Linear("out of memory for the Cholesky factorisation".into());
        let Some(mut values) = Pages::zeroed(symbolic.len_val()) else { return (Err(oom()), None) };
        let Ok(mut buf) =
            MemBuffer::try_new(symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()))
        else {
            return (Err(oom()), None);
        };
        // the factor's pages are mapped on a second thread while this one computes (solve::pages)
        let range = values.range();
        let (numeric, r) = std::thread::scope(|s| {
            let r = s.spawn(move || {
                Pages::populate(range);
                beside()
            });
            let numeric = symbolic.factorize_numeric_llt(
                &mut values,
                k.as_ref(),
                Side::Lower,
                Default::default(),
                Par::Seq,
                MemStack::new(&mut buf),
                Default::default(),
            );
            (numeric.map(|_| ()), r.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
        });
        (Factor::finish(symbolic, values, numeric, n, last, fwd), Some(r))
    }

    fn finish(
        symbolic: SymbolicCholesky<usize>,
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
        Ok(Factor { symbolic, values, scratch: Mutex::new((1, scratch)), n, last, fwd })
    }

    /// Entries of L kept (supernodal blocks included).
    pub fn len_val(&self) -> usize {
        self.values.len()
    }

    /// Floating-point operations of the numeric factorisation, Σ_j c_j² over the columns j of L with
    /// c_j entries each (diagonal included; the count CHOLMOD reports), and the entries of L without
    /// the supernodal blocks' upper triangles, Σ_j c_j.
    pub fn flops_and_entries(&self) -> (f64, f64) {
        let Some(llt) = self.supernodal() else { return (f64::NAN, f64::NAN) };
        let (mut flops, mut entries) = (0.0, 0.0);
        for s in 0..llt.symbolic().n_supernodes() {
            let sn = llt.supernode(s);
            let (width, below) = (sn.val().ncols(), sn.pattern().len());
            for jj in 0..width {
                let c = (width - jj + below) as f64;
                flops += c * c;
                entries += c;
            }
        }
        (flops, entries)
    }

    /// The unknowns ordered last (see [`Factor::with_last`]).
    pub fn last(&self) -> &[usize] {
        &self.last
    }

    fn supernodal(&self) -> Option<SupernodalLltRef<'_, usize, f64>> {
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => Some(SupernodalLltRef::new(s, &self.values)),
            SymbolicCholeskyRaw::Simplicial(_) => None,
        }
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
        if scratch.0 < cols {
            scratch.1 = MemBuffer::try_new(self.symbolic.solve_in_place_scratch::<f64>(cols, Par::Seq))
                .map_err(|_| Error::Linear("out of memory for the solve scratch".into()))?;
            scratch.0 = cols;
        }
        let (y, stack) = (MatMut::from_column_major_slice_mut(y, self.n, cols), MemStack::new(&mut scratch.1));
        if forward {
            llt.l_solve_with_conj(Conj::No, y, Par::Seq, stack);
        } else {
            llt.l_transpose_solve_with_conj(Conj::No, y, Par::Seq, stack);
        }
        Ok(())
    }

    /// x ← K⁻¹ x for one vector.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let llt = LltRef::new(&self.symbolic, &self.values);
        let mut buf = self.scratch.lock().unwrap_or_else(|e| e.into_inner());
        llt.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, self.n, 1),
            Par::Seq,
            MemStack::new(&mut buf.1),
        );
    }

    /// X ← K⁻¹ X for a block of right-hand sides.
    pub fn solve_many(&self, x: MatMut<'_, f64>) {
        let llt = LltRef::new(&self.symbolic, &self.values);
        let mut buf = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(x.ncols(), Par::Seq));
        llt.solve_in_place_with_conj(Conj::No, x, Par::Seq, MemStack::new(&mut buf));
    }
}

#[cfg(test)]
mod tests {
    use super::super::ordering::nested_dissection;
    use super::*;
    use crate::sparse::{csc_from_triplets, matvec};

    /// Plane-elasticity-like test matrix: a 2D grid (m × m nodes) Laplacian, two coupled unknowns per node
    /// (numbered consecutively), shifted to be SPD.
    fn grid(m: usize) -> SparseColMat<usize, f64> {
        let node = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let a = node(i, j);
                for c in 0..2 {
                    t.push((2 * a + c, 2 * a + c, 4.5));
                }
                t.push((2 * a, 2 * a + 1, 0.25));
                t.push((2 * a + 1, 2 * a, 0.25));
                for (di, dj) in [(0, 1), (1, 0)] {
                    if i + di < m && j + dj < m {
                        let b = node(i + di, j + dj);
                        for c in 0..2 {
                            t.push((2 * a + c, 2 * b + c, -1.0));
                            t.push((2 * b + c, 2 * a + c, -1.0));
                        }
                    }
                }
            }
        }
        csc_from_triplets(2 * m * m, &t)
    }

    fn residual(k: &SparseColMat<usize, f64>, f: &Factor) -> f64 {
        let n = k.nrows();
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let mut x = b.clone();
        f.solve_in_place(&mut x);
        let mut r = vec![0.0; n];
        matvec(k, &x, &mut r);
        r.iter().zip(&b).map(|(r, b)| (r - b).abs()).fold(0.0, f64::max)
    }

    /// The blocked steps (`solve::free::Block`) rely on this: in a solve with B columns each column's
    /// result depends neither on the other columns nor on its position.
    #[test]
    fn block_columns_are_independent_of_neighbours_and_position() {
        let k = grid(70);
        let n = k.nrows();
        let f = Factor::with_last(&k, &[0, 2, 4, 6]).unwrap();
        let b: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let cols = 16;
        let mut y: Vec<f64> =
            (0..n * cols).map(|i| if (i / n).is_multiple_of(2) { b[i % n] } else { ((i * 13) % 7) as f64 }).collect();
        f.forward_block(&mut y, cols).unwrap();
        f.backward_block(&mut y, cols).unwrap();
        let bits = |c: usize| y[c * n..(c + 1) * n].iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        for c in (2..cols).step_by(2) {
            assert_eq!(bits(0), bits(c), "column {c}");
        }
    }

    /// The factor with the ordering of `fill_order` on the groups `first`.
    fn ordered(k: &SparseColMat<usize, f64>, nested: bool, first: &[usize]) -> Result<Factor> {
        Factor::with_order(k, &[], fill_order(&Graph::of_matrix(k, first), nested)?)
    }

    /// Groups of the two unknowns of a grid node.
    fn pairs(n: usize) -> Vec<usize> {
        (0..=n).step_by(2).collect()
    }

    fn singles(n: usize) -> Vec<usize> {
        (0..=n).collect()
    }

    #[test]
    fn nested_dissection_orders_and_solves() {
        let k = grid(40);
        let (fwd, inv) = nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).expect("METIS ordering");
        assert!(fwd.iter().enumerate().all(|(new, &old)| inv[old] == new));
        let nd = ordered(&k, true, &pairs(k.nrows())).unwrap();
        let amd = ordered(&k, false, &pairs(k.nrows())).unwrap();
        assert!(residual(&k, &nd) < 1e-12 && residual(&k, &amd) < 1e-12);
    }

    #[test]
    fn nested_dissection_is_deterministic_across_threads() {
        let k = grid(30);
        let reference = nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).unwrap();
        let runs: Vec<_> = std::thread::scope(|s| {
            let h: Vec<_> = (0..4)
                .map(|_| s.spawn(|| nested_dissection(&Graph::of_matrix(&k, &pairs(k.nrows()))).unwrap()))
                .collect();
            h.into_iter().map(|h| h.join().unwrap()).collect()
        });
        assert!(runs.iter().all(|r| *r == reference));
    }

    #[test]
    fn degenerate_graphs_fall_back_to_amd() {
        let diag = |n: usize| csc_from_triplets(n, &(0..n).map(|i| (i, i, 2.0)).collect::<Vec<_>>());
        for n in [0, 1, 2, 5] {
            assert!(nested_dissection(&Graph::of_matrix(&diag(n), &singles(n))).is_none());
            let f = ordered(&diag(n), true, &singles(n)).unwrap();
            assert!(residual(&diag(n), &f) < 1e-15);
        }
        // One coupled pair: a single METIS vertex, no edges.
        let pair = csc_from_triplets(2, &[(0, 0, 2.0), (1, 1, 2.0), (0, 1, 1.0), (1, 0, 1.0)]);
        assert!(nested_dissection(&Graph::of_matrix(&pair, &[0, 2])).is_none());
        assert!(residual(&pair, &ordered(&pair, true, &[0, 2]).unwrap()) < 1e-15);
        // Three unknowns: METIS on a 2-vertex graph.
        let three = csc_from_triplets(
            3,
            &[(0, 0, 4.0), (1, 1, 4.0), (2, 2, 4.0), (1, 2, 1.0), (2, 1, 1.0), (0, 2, 1.0), (2, 0, 1.0)],
        );
        assert!(residual(&three, &ordered(&three, true, &[0, 1, 3]).unwrap()) < 1e-14);
    }
}

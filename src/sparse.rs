//! Sparse and vector kernels shared by assembly, the factor and the studies: a CSC matrix from
//! triplets, y = K x, and the scaled Euclidean norm.

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// Square CSC matrix from (row, col, value) triplets, duplicates summed: a counting sort by column,
/// then a sort of each (short) column by row. O(nnz · log(column length)).
pub fn csc_from_triplets(n: usize, trip: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let mut start = vec![0usize; n + 1];
    for &(_, c, _) in trip {
        start[c + 1] += 1;
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    let mut slot = start.clone();
    let mut entries = vec![(0usize, 0.0f64); trip.len()];
    for &(r, c, v) in trip {
        entries[slot[c]] = (r, v);
        slot[c] += 1;
    }
    let (mut col_ptr, mut row_idx, mut val) =
        (Vec::with_capacity(n + 1), Vec::with_capacity(trip.len() / 2), Vec::with_capacity(trip.len() / 2));
    col_ptr.push(0);
    for j in 0..n {
        let col = &mut entries[start[j]..start[j + 1]];
        col.sort_unstable_by_key(|e| e.0);
        for &(r, v) in col.iter() {
            if row_idx.len() > col_ptr[j] && *row_idx.last().expect("nonempty column") == r {
                *val.last_mut().expect("nonempty column") += v;
            } else {
                row_idx.push(r);
                val.push(v);
            }
        }
        col_ptr.push(row_idx.len());
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), val)
}

/// y = K x for a CSC matrix.
pub fn matvec(k: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    let s = k.symbolic();
    let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
    for j in 0..s.ncols() {
        let xj = x[j];
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += val[p] * xj;
        }
    }
}

/// xᵀy.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

/// xᵀ K x, as Σ_j x_j (column j of K)·x: one pass over K that only reads (no K x vector is formed).
pub fn energy(k: &SparseColMat<usize, f64>, x: &[f64]) -> f64 {
    let s = k.symbolic();
    let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
    (0..s.ncols())
        .map(|j| x[j] * ri[cp[j]..cp[j + 1]].iter().zip(&val[cp[j]..cp[j + 1]]).map(|(&i, v)| v * x[i]).sum::<f64>())
        .sum()
}

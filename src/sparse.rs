//! Sparse and vector kernels shared by assembly, the factor and the studies: a CSC matrix from
//! triplets, the lower triangle of a symmetric matrix (what a run keeps of K: the factorisation reads
//! only it), y = K x and xᵀK x from both triangles or from the lower one.

use faer::sparse::{SparseColMat, SymbolicSparseColMat, SymbolicSparseColMatRef};

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

/// The lower triangle (row ≥ column) of the pattern `p` (columns sorted), a copy.
pub fn lower_pattern(p: SymbolicSparseColMatRef<'_, usize>) -> SymbolicSparseColMat<usize> {
    let (cp, ri) = (p.col_ptr(), p.row_idx());
    let n = p.ncols();
    let (mut col_ptr, mut row_idx) = (Vec::with_capacity(n + 1), Vec::with_capacity((ri.len() + n) / 2));
    col_ptr.push(0);
    for j in 0..n {
        row_idx.extend(ri[cp[j]..cp[j + 1]].iter().filter(|&&i| i >= j));
        col_ptr.push(row_idx.len());
    }
    SymbolicSparseColMat::new_checked(p.nrows(), n, col_ptr, None, row_idx)
}

/// The values `val` of a matrix with pattern `p` kept on its lower triangle only (in the order of
/// [`lower_pattern`]), compacted in place: the upper triangle's memory is handed back.
pub fn lower_values(p: SymbolicSparseColMatRef<'_, usize>, mut val: Vec<f64>) -> Vec<f64> {
    let (cp, ri) = (p.col_ptr(), p.row_idx());
    let mut at = 0;
    for j in 0..p.ncols() {
        for q in cp[j]..cp[j + 1] {
            if ri[q] >= j {
                val[at] = val[q];
                at += 1;
            }
        }
    }
    val.truncate(at);
    val.shrink_to_fit();
    val
}

/// y = K x for the symmetric K given by its lower triangle `k` (columns sorted). Each y_i sums
/// K_ij x_j over j in increasing order, as [`matvec`] does on both triangles: for a K whose stored
/// triangles mirror each other bit for bit the two agree bit for bit.
pub fn symmetric_matvec(k: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    let s = k.symbolic();
    let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
    for j in 0..s.ncols() {
        let xj = x[j];
        // row j's sum, continued in a register: the column's other rows are i ≠ j
        let mut yj = y[j];
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            if i == j {
                yj += val[p] * xj;
            } else {
                // K_ji = K_ij: the term x_i of row j (after its terms from columns < j), and x_j of row i
                yj += val[p] * x[i];
                y[i] += val[p] * xj;
            }
        }
        y[j] = yj;
    }
}

/// xᵀ K x for the symmetric K given by its lower triangle `k` (columns sorted), summed as
/// Σ_j x_j (Σ_i K_ij x_i) with i and j increasing (the terms of row j above the diagonal gathered in
/// `upper[j]` from the columns before j): for a K whose stored triangles mirror each other bit for bit,
/// the same sums as one pass over both triangles.
pub fn symmetric_energy(k: &SparseColMat<usize, f64>, x: &[f64]) -> f64 {
    let s = k.symbolic();
    let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
    // -0.0 is the sum of no terms (as `Iterator::sum`), so the first term is taken exactly
    let mut upper = vec![-0.0f64; s.ncols()];
    let mut total = -0.0f64;
    for j in 0..s.ncols() {
        let mut col = upper[j];
        for p in cp[j]..cp[j + 1] {
            let i = ri[p];
            col += val[p] * x[i];
            if i > j {
                upper[i] += val[p] * x[j];
            }
        }
        total += x[j] * col;
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Σ_j x_j (column j of K)·x over both triangles: the reference the one-triangle kernel must match.
    fn energy_both(k: &SparseColMat<usize, f64>, x: &[f64]) -> f64 {
        let s = k.symbolic();
        let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
        (0..s.ncols())
            .map(|j| {
                x[j] * ri[cp[j]..cp[j + 1]].iter().zip(&val[cp[j]..cp[j + 1]]).map(|(&i, v)| v * x[i]).sum::<f64>()
            })
            .sum()
    }

    /// The system shall compute K x and xᵀK x from K's lower triangle with the same sums, bit for bit, as
    /// from both triangles of a K whose triangles mirror each other, and keep exactly the lower entries.
    #[test]
    fn the_lower_triangle_gives_the_products_of_both() {
        let n = 40;
        let mut trip = Vec::new();
        for j in 0..n {
            for i in j..n {
                // a sparse, irregular pattern with values of mixed sign and magnitude
                if i == j || (i * 7 + j * 3) % 5 == 0 {
                    let v = if i == j { 10.0 + j as f64 } else { ((i * 31 + j * 17) % 13) as f64 / 7.0 - 0.9 };
                    trip.push((i, j, v * 1.1f64.powi(i as i32 - j as i32)));
                    if i != j {
                        trip.push((j, i, v * 1.1f64.powi(i as i32 - j as i32)));
                    }
                }
            }
        }
        let full = csc_from_triplets(n, &trip);
        let lower_trip: Vec<_> = trip.iter().copied().filter(|t| t.0 >= t.1).collect();
        let expected = csc_from_triplets(n, &lower_trip);
        let pattern = lower_pattern(full.symbolic());
        let lower = SparseColMat::new(pattern, lower_values(full.symbolic(), full.val().to_vec()));
        assert_eq!(lower.symbolic().col_ptr(), expected.symbolic().col_ptr());
        assert_eq!(lower.symbolic().row_idx(), expected.symbolic().row_idx());
        assert_eq!(lower.val(), expected.val());
        let x: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 / 3.0 - 1.7).collect();
        let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
        matvec(&full, &x, &mut a);
        symmetric_matvec(&lower, &x, &mut b);
        assert!(a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits()), "{a:?} vs {b:?}");
        assert_eq!(energy_both(&full, &x).to_bits(), symmetric_energy(&lower, &x).to_bits());
        // a zero vector: the sign of the zero as well
        let z = vec![0.0; n];
        assert_eq!(energy_both(&full, &z).to_bits(), symmetric_energy(&lower, &z).to_bits());
    }
}

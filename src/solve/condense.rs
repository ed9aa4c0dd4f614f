//! Condensation onto the contact unknowns: with E the injection of the n_c contact unknowns (one
//! tangential displacement per Γ_C edge), the friction operator
//!   C = EᵀK⁻¹E   (dense, SPD, n_c × n_c),
//! taken from the factor, which orders the contact unknowns last (`Factor::with_last`): with L_cc its
//! trailing block and W = L_cc⁻¹ (dense triangular inverse, n_c³/3 flops),
//!   C = (L_cc L_ccᵀ)⁻¹ = WᵀW,
//! because L_cc L_ccᵀ is the Schur complement of the other unknowns, the inverse of (K⁻¹)_cc. No solve
//! with K is made. W is kept: with y = L⁻¹Pᵀl (the forward half of a solve) the contact trace of
//! u_f = K⁻¹l is Wᵀy_c, and L⁻¹E μ = [0; Wμ] (`free`).

use super::cholesky::Factor;
use crate::error::{Error, Result};
use nalgebra::DMatrix;

/// C (symmetrised) and W = L_cc⁻¹, rows and columns in the order of the contact unknowns.
#[derive(Clone)]
pub struct Condensation {
    pub c: DMatrix<f64>,
    pub w: DMatrix<f64>,
}

/// C and W of the contact unknowns `dofs`; the factor must order exactly them last, in this order.
pub fn condense(dofs: &[usize], factor: &Factor) -> Result<Condensation> {
    if factor.last() != dofs {
        return Err(Error::Linear("internal: the factor does not order the contact unknowns last".into()));
    }
    let nc = dofs.len();
    let l = factor.last_block()?;
    let w = l
        .solve_lower_triangular(&DMatrix::identity(nc, nc))
        .ok_or_else(|| Error::Linear("the contact block of the Cholesky factor is singular".into()))?;
    let c = w.transpose() * &w;
    Ok(Condensation { c: 0.5 * (&c + c.transpose()), w })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sparse::csc_from_triplets;

    /// A 2D grid Laplacian with two coupled unknowns per node (SPD).
    fn grid(m: usize) -> faer::sparse::SparseColMat<usize, f64> {
        let node = |i: usize, j: usize| i * m + j;
        let mut t = Vec::new();
        for i in 0..m {
            for j in 0..m {
                let a = node(i, j);
                t.extend([
                    (2 * a, 2 * a, 4.5),
                    (2 * a + 1, 2 * a + 1, 4.5),
                    (2 * a, 2 * a + 1, 0.25),
                    (2 * a + 1, 2 * a, 0.25),
                ]);
                for (di, dj) in [(0, 1), (1, 0)] {
                    if i + di < m && j + dj < m {
                        let b = node(i + di, j + dj);
                        for c in 0..2 {
                            t.extend([(2 * a + c, 2 * b + c, -1.0), (2 * b + c, 2 * a + c, -1.0)]);
                        }
                    }
                }
            }
        }
        csc_from_triplets(2 * m * m, &t)
    }

    #[test]
    fn from_the_factor_equals_solves_with_k() {
        let k = grid(24);
        let n = k.nrows();
        // a boundary row's first components, in a scrambled order
        let dofs: Vec<usize> = [5, 0, 11, 3, 17, 8, 23, 14].iter().map(|&j| 2 * j).collect();
        let factor = Factor::with_last(&k, &dofs).unwrap();
        let Condensation { c, w } = condense(&dofs, &factor).unwrap();
        let mut worst = 0.0f64;
        for (j, &dj) in dofs.iter().enumerate() {
            // column j of K⁻¹E by a full solve, and by the halves with the unit force put in between
            let mut col = vec![0.0; n];
            col[dj] = 1.0;
            factor.solve_in_place(&mut col);
            let mut halves = vec![0.0; n];
            for i in 0..dofs.len() {
                halves[n - dofs.len() + i] = w[(i, j)];
            }
            factor.backward_solve(&mut halves).unwrap();
            for (i, &di) in dofs.iter().enumerate() {
                worst = worst.max((c[(i, j)] - col[di]).abs());
            }
            worst = worst.max(col.iter().zip(&halves).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max));
        }
        // K⁻¹ entries by backward-stable Cholesky solves of a matrix with condition ~10: a few ulps of
        // the largest entry (~0.3) apart, so 1e-14 absolute fails on any wrong sign, index or block
        assert!(worst <= 1e-14, "{worst}");
        assert!(condense(&dofs[1..], &factor).is_err());
    }
}

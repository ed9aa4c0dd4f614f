//! Condensation onto the contact unknowns: with E the injection of the n_c contact unknowns (one
//! tangential displacement per Γ_C edge),
//!   Z = K⁻¹E (n × n_c)   and   C = EᵀK⁻¹E = EᵀZ (dense, SPD, n_c × n_c).
//! C is the operator of the friction problem (`friction`); Z gives the free response's contact trace
//! Eᵀu_f = Zᵀl and the friction correction K⁻¹Eμ = Zμ without further solves (`free`).
//!
//! From the factor, when it orders the contact unknowns last (`Factor::with_last`): with L_cc its
//! trailing block, W = L_cc⁻¹ (dense triangular inverse, n_c³/3 flops),
//!   C = (L_cc L_ccᵀ)⁻¹ = WᵀW,   Z = P L⁻ᵀ [0; W]   (one blocked backward half-solve),
//! since L⁻¹E = [0; W] for a lower-triangular L. Otherwise, blocked solves with n_c right-hand sides.

use super::factor::Factor;
use crate::error::{Error, Result};
use faer::Mat;
use nalgebra::DMatrix;

/// Largest Z kept in memory (entries); beyond it a second triangular solve per step is cheaper in memory.
pub const Z_MAX_ENTRIES: usize = 50_000_000;

/// C, and Z when it fits in [`Z_MAX_ENTRIES`] (column-major, n × n_c).
pub struct Condensation {
    pub c: DMatrix<f64>,
    pub z: Option<Vec<f64>>,
}

/// C (symmetrised) and Z of the contact unknowns `dofs` of an n-unknown K.
pub fn condense(dofs: &[usize], factor: &Factor, n: usize) -> Result<Condensation> {
    let nc = dofs.len();
    let keep_z = n.saturating_mul(nc) <= Z_MAX_ENTRIES;
    if factor.last() != dofs {
        return Ok(by_solves(dofs, factor, n, keep_z));
    }
    let l = factor.last_block()?;
    let w = l
        .solve_lower_triangular(&DMatrix::identity(nc, nc))
        .ok_or_else(|| Error::Linear("the contact block of the Cholesky factor is singular".into()))?;
    let c = w.transpose() * &w;
    let z = if keep_z {
        let mut x = Mat::<f64>::zeros(n, nc);
        for j in 0..nc {
            for i in j..nc {
                x[(n - nc + i, j)] = w[(i, j)];
            }
        }
        factor.backward_solve_many(x.as_mut())?;
        let mut z = vec![0.0; n * nc];
        for j in 0..nc {
            z[j * n..(j + 1) * n].iter_mut().enumerate().for_each(|(r, v)| *v = x[(r, j)]);
        }
        Some(z)
    } else {
        None
    };
    Ok(Condensation { c: 0.5 * (&c + c.transpose()), z })
}

/// C and Z by blocked solves K⁻¹E, 64 columns at a time (any ordering).
fn by_solves(dofs: &[usize], factor: &Factor, n: usize, keep_z: bool) -> Condensation {
    let nc = dofs.len();
    let mut z = if keep_z { Some(vec![0.0; n * nc]) } else { None };
    let mut c = DMatrix::zeros(nc, nc);
    const BLOCK: usize = 64;
    for start in (0..nc).step_by(BLOCK) {
        let end = (start + BLOCK).min(nc);
        let mut rhs = Mat::<f64>::zeros(n, end - start);
        for j in start..end {
            rhs[(dofs[j], j - start)] = 1.0;
        }
        factor.solve_many(rhs.as_mut());
        for j in start..end {
            for i in 0..nc {
                c[(i, j)] = rhs[(dofs[i], j - start)];
            }
            if let Some(z) = z.as_mut() {
                for r in 0..n {
                    z[j * n + r] = rhs[(r, j - start)];
                }
            }
        }
    }
    let c = 0.5 * (&c + c.transpose());
    Condensation { c, z }
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
                t.extend([(2 * a, 2 * a, 4.5), (2 * a + 1, 2 * a + 1, 4.5), (2 * a, 2 * a + 1, 0.25), (2 * a + 1, 2 * a, 0.25)]);
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
    fn from_the_factor_equals_by_solves() {
        let k = grid(24);
        let n = k.nrows();
        // a boundary row's first components, in a scrambled order
        let dofs: Vec<usize> = [5, 0, 11, 3, 17, 8, 23, 14].iter().map(|&j| 2 * j).collect();
        let fast = condense(&dofs, &Factor::with_last(&k, &dofs).unwrap(), n).unwrap();
        let slow = condense(&dofs, &Factor::new(&k).unwrap(), n).unwrap();
        // both are K⁻¹ entries from backward-stable Cholesky solves of a matrix with condition ~10:
        // they agree to a few hundred ulps
        let scale = slow.c.amax();
        assert!((&fast.c - &slow.c).amax() <= 1e-13 * scale, "{}", (&fast.c - &slow.c).amax());
        let (zf, zs) = (fast.z.unwrap(), slow.z.unwrap());
        let dz = zf.iter().zip(&zs).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(dz <= 1e-13 * scale, "{dz}");
    }
}

//! Condensation onto the contact unknowns: with E the injection of the n_c contact unknowns (one
//! tangential displacement per Γ_C edge),
//!   Z = K⁻¹E (n × n_c)   and   C = EᵀK⁻¹E = EᵀZ (dense, SPD, n_c × n_c),
//! computed with blocked multi-right-hand-side solves of the once-made factor. C is the operator of
//! the friction problem (`friction`); Z gives the free response's contact trace Eᵀu_f = Zᵀl and the
//! friction correction K⁻¹Eμ = Zμ without further solves (`free`).

use super::factor::Factor;
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
pub fn condense(dofs: &[usize], factor: &Factor, n: usize) -> Condensation {
    let nc = dofs.len();
    let keep_z = n.saturating_mul(nc) <= Z_MAX_ENTRIES;
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

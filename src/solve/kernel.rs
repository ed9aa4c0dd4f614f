//! The rigid motions a floating body keeps (a body held only by contact and symmetry parts, no
//! Dirichlet part), and the generalized inverse of K that solves with it (FETI, Farhat–Roux).
//!
//! A rigid motion r(x) = (a − θ(y − y_c), b + θ(x − x_c)) is linear, so CR interpolates it exactly
//! (zero jumps, zero strain): a_h(r, v) = 0 for every v. Those that also satisfy the homogeneous strong
//! constraints of V_h (r·n_e(m_e) = 0 where a bilateral Γ_C edge carries only its tangential unknown)
//! span ker K, the k ≤ 3 columns of R. With k pinned unknowns P (chosen so that R_P is nonsingular),
//! K_# is K with the rows and columns of P replaced by their diagonal: it is SPD, and
//!   K⁺ = [K_ff⁻¹ 0; 0 0]   (K_# solves, then u_P ← 0)
//! is a generalized inverse (K K⁺ K = K). Every solution of K u = l − Eλ is u = K⁺(l − Eλ) + Rα, and
//! one exists iff Rᵀ(l − Eλ) = 0: the condensed problem gains the equality Gᵀλ = e with G = EᵀR and
//! e = Rᵀl (`friction::floating`). R is scaled so that G has orthonormal columns.

use crate::fem::space::{CrSpace, EdgeDof};
use crate::mesh::Mesh;
use faer::sparse::SparseColMat;
use nalgebra::{DMatrix, SymmetricEigen};

/// A basis vector of the rigid motions below this (relative to the largest) is constrained.
const RANK_TOL: f64 = 1e-10;

/// ker K of a floating body: R (unknowns × k), the pinned unknowns, and each column as a motion.
#[derive(Clone, Debug)]
pub struct Kernel {
    /// R, one column per rigid motion, n_dofs rows.
    pub r: DMatrix<f64>,
    /// The motion of each column.
    pub motions: Motions,
    /// The pinned unknowns (k of them).
    pub pinned: Vec<usize>,
}

/// The velocity of the basis motion j ∈ {x, y, rotation (scaled by 1/L)} at point p.
fn basis(j: usize, p: [f64; 2], c: [f64; 2], len: f64) -> [f64; 2] {
    match j {
        0 => [1.0, 0.0],
        1 => [0.0, 1.0],
        _ => [-(p[1] - c[1]) / len, (p[0] - c[0]) / len],
    }
}

impl Kernel {
    /// The rigid motions of `space` on `mesh` (`None` when there are none: a Dirichlet part fixes them,
    /// or the strong constraints do).
    pub fn of(mesh: &Mesh, space: &CrSpace) -> Option<Kernel> {
        if space.n_dirichlet > 0 || space.n_dofs == 0 {
            return None;
        }
        let n_pts = mesh.points.len().max(1) as f64;
        let c = mesh.points.iter().fold([0.0; 2], |a, p| [a[0] + p[0] / n_pts, a[1] + p[1] / n_pts]);
        let len =
            mesh.points.iter().map(|p| (p[0] - c[0]).hypot(p[1] - c[1])).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        // the strong constraints r·n_e = 0 on tangential-only edges: A (m × 3), its null space
        let mut ata = DMatrix::<f64>::zeros(3, 3);
        for (e, d) in space.edge_dof.iter().enumerate() {
            if let EdgeDof::Tangential { tau, .. } = d {
                let (n, m) = ([tau[1], -tau[0]], mesh.midpoint(e));
                let row: Vec<f64> = (0..3).map(|j| basis(j, m, c, len)).map(|v| v[0] * n[0] + v[1] * n[1]).collect();
                for i in 0..3 {
                    for j in 0..3 {
                        ata[(i, j)] += row[i] * row[j];
                    }
                }
            }
        }
        let eig = SymmetricEigen::new(ata.clone());
        let top = eig.eigenvalues.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let free: Vec<usize> =
            (0..3).filter(|&i| eig.eigenvalues[i] <= RANK_TOL * top.max(0.0) || top == 0.0).collect();
        if free.is_empty() {
            return None;
        }
        let mut motions = DMatrix::from_fn(3, free.len(), |i, j| eig.eigenvectors[(i, free[j])]);
        let mut r = Self::interpolate(mesh, space, &motions, c, len);
        // G = EᵀR with orthonormal columns: R ← R T⁻¹, GᵀG = TᵀT (the contact trace sees every motion
        // of a body in contact; one it does not see is refused by `Kernel::unseen`)
        let dofs = space.contact_dofs();
        let g = DMatrix::from_fn(dofs.len(), r.ncols(), |i, j| r[(dofs[i], j)]);
        if let Some(ch) = (g.transpose() * &g).cholesky() {
            let tinv = ch.l().transpose().try_inverse().unwrap_or_else(|| DMatrix::identity(r.ncols(), r.ncols()));
            r = &r * &tinv;
            motions = &motions * &tinv;
        }
        motions.row_mut(2).iter_mut().for_each(|v| *v /= len);
        let pinned = pivots(space, &r);
        (pinned.len() == r.ncols()).then_some(Kernel {
            r,
            motions: Motions { m: motions, centre: c, size: len },
            pinned,
        })
    }

    /// R: the motions (columns of `m`, in the scaled basis) at every unknown.
    fn interpolate(mesh: &Mesh, space: &CrSpace, m: &DMatrix<f64>, c: [f64; 2], len: f64) -> DMatrix<f64> {
        let mut r = DMatrix::zeros(space.n_dofs, m.ncols());
        for (e, d) in space.edge_dof.iter().enumerate() {
            let p = mesh.midpoint(e);
            for col in 0..m.ncols() {
                let v = (0..3).fold([0.0; 2], |a, j| {
                    let b = basis(j, p, c, len);
                    [a[0] + m[(j, col)] * b[0], a[1] + m[(j, col)] * b[1]]
                });
                for (k, t) in d.terms() {
                    r[(k, col)] = t[0] * v[0] + t[1] * v[1];
                }
            }
        }
        r
    }

    /// Number of rigid motions k.
    pub fn len(&self) -> usize {
        self.r.ncols()
    }

    /// Always false (a kernel has k ≥ 1 columns).
    pub fn is_empty(&self) -> bool {
        self.r.ncols() == 0
    }

    /// The rows of R at `dofs` (G = EᵀR for the contact unknowns).
    pub fn rows(&self, dofs: &[usize]) -> DMatrix<f64> {
        DMatrix::from_fn(dofs.len(), self.len(), |i, j| self.r[(dofs[i], j)])
    }

    /// True if some rigid motion has no contact trace (G rank-deficient): nothing can ever hold it.
    pub fn unseen(&self, dofs: &[usize]) -> bool {
        let g = self.rows(dofs);
        (g.transpose() * g).cholesky().is_none()
    }

    /// K_#: K (lower triangle) with the pinned rows and columns zero except their diagonal.
    pub fn pin(&self, k: &SparseColMat<usize, f64>) -> SparseColMat<usize, f64> {
        let mut pinned = vec![false; k.nrows()];
        self.pinned.iter().for_each(|&p| pinned[p] = true);
        let sym = k.symbolic();
        let mut val = k.val().to_vec();
        for j in 0..k.ncols() {
            for idx in sym.col_ptr()[j]..sym.col_ptr()[j + 1] {
                let i = sym.row_idx()[idx];
                if i != j && (pinned[i] || pinned[j]) {
                    val[idx] = 0.0;
                }
            }
        }
        SparseColMat::new(sym.to_owned().expect("a valid pattern stays valid"), val)
    }

    /// u ← u with the pinned unknowns zeroed (K⁺ from a solve with K_#), plus Rα.
    pub fn complete(&self, u: &mut [f64], alpha: &[f64]) {
        if u.is_empty() {
            return;
        }
        self.pinned.iter().for_each(|&p| u[p] = 0.0);
        for (j, a) in alpha.iter().enumerate() {
            u.iter_mut().zip(self.r.column(j).iter()).for_each(|(ui, r)| *ui += a * r);
        }
    }

    /// e = Rᵀl for a load given on `support` (values `l`).
    pub fn net(&self, support: &[usize], l: &[f64]) -> Vec<f64> {
        (0..self.len()).map(|j| support.iter().zip(l).map(|(&k, v)| self.r[(k, j)] * v).sum()).collect()
    }

    /// e = Rᵀl for a load on every unknown.
    pub fn net_full(&self, l: &[f64]) -> Vec<f64> {
        (0..self.len()).map(|j| self.r.column(j).iter().zip(l).map(|(r, v)| r * v).sum()).collect()
    }
}

/// The rigid motions of the columns of R: column j is (a, b, θ) = `m[:, j]`, the motion
/// (a − θ(y − y_c), b + θ(x − x_c)) about `centre`.
#[derive(Clone, Debug)]
pub struct Motions {
    pub m: DMatrix<f64>,
    pub centre: [f64; 2],
    /// The body's size (largest distance of a vertex from the centre), to compare θ with a translation.
    pub size: f64,
}

impl Motions {
    /// Number of motions k.
    pub fn len(&self) -> usize {
        self.m.ncols()
    }

    /// Always false (k ≥ 1).
    pub fn is_empty(&self) -> bool {
        self.m.ncols() == 0
    }

    /// The motion Σ_j v_j R_j named: a translation or a rotation about a point.
    pub fn describe(&self, v: &[f64]) -> String {
        let m: Vec<f64> = (0..3).map(|i| (0..self.len()).map(|j| self.m[(i, j)] * v[j]).sum::<f64>()).collect();
        let (a, b, th) = (m[0], m[1], m[2]);
        let t = a.hypot(b);
        if th == 0.0 || th.abs() * self.size <= 1e-9 * t {
            let dir = if b.abs() <= 1e-9 * t {
                "x".to_string()
            } else if a.abs() <= 1e-9 * t {
                "y".into()
            } else {
                format!("({:.3}, {:.3})", a / t, b / t)
            };
            return format!("the translation in {dir}");
        }
        let [xc, yc] = self.centre;
        format!("the rotation about ({:.4e}, {:.4e})", xc - b / th, yc + a / th)
    }

    /// The free rigid motions named, one per column (for `check`).
    pub fn names(&self) -> Vec<String> {
        let unit = |j: usize| (0..self.len()).map(|i| f64::from(u8::from(i == j))).collect::<Vec<f64>>();
        (0..self.len()).map(|j| self.describe(&unit(j))).collect()
    }
}

/// k unknowns off Γ_C with R_P well conditioned: pivoted Gram–Schmidt on the rows of R (each time the
/// row of largest norm after removing the directions already pinned).
fn pivots(space: &CrSpace, r: &DMatrix<f64>) -> Vec<usize> {
    let k = r.ncols();
    let mut candidate = vec![true; space.n_dofs];
    space.contact_dofs().iter().for_each(|&d| candidate[d] = false);
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let mut pinned = Vec::new();
    for _ in 0..k {
        let mut best = (0.0, usize::MAX, vec![]);
        for i in (0..space.n_dofs).filter(|&i| candidate[i]) {
            let mut row: Vec<f64> = (0..k).map(|j| r[(i, j)]).collect();
            for b in &basis {
                let p: f64 = row.iter().zip(b).map(|(x, y)| x * y).sum();
                row.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
            }
            let nrm = row.iter().map(|x| x * x).sum::<f64>().sqrt();
            if nrm > best.0 {
                best = (nrm, i, row);
            }
        }
        if best.1 == usize::MAX {
            break;
        }
        candidate[best.1] = false;
        pinned.push(best.1);
        basis.push(best.2.iter().map(|x| x / best.0).collect());
    }
    pinned
}

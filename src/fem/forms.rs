//! The forms of the energy audit on **full** midpoint fields U (a 2-vector at every edge midpoint,
//! constrained edges included, as written to results files), matrix-free and independent of K:
//!
//! * A(U, V) = Σ_T |T| σ(∇U):∇V + Σ_{e interior ∪ Γ_D} 2ρμ Σ_q ω_q [U](x_q)·[V](x_q)  (2-point Gauss, exact;
//!   [U] = U on a Dirichlet edge): the paper's a_h, as [`FullForm::apply`] = A U edge by edge;
//! * B(p, V) = Σ_{e ⊂ Γ_D with data} 2ρμ Σ_q ω_q p_q·V(x_q)  (3-point Gauss at the data points, as
//!   `fem::lifting`'s b_D): [`FullForm::data_vector`] = B(p, ·) edge by edge;
//! * C(p, r) = Σ_{e ⊂ Γ_D with data} 2ρμ Σ_q ω_q p_q·r_q.
//!
//! With them the stabilised energy of the scheme with Dirichlet data p = u_D(tₙ) is
//!   E(U, p) = ½A(U, U) − B(p, U) + ½C(p, p) = ½Σ_T ∫σ:ε + ½Σ_int (2ρμ/h_e)∫|[U]|² + ½Σ_D (2ρμ/h_e)∫|U − u_D|²,
//! a quadratic form Q of the pair X = (U, p); without data, E = ½a_h(U, U).

use super::elasticity::Elasticity;
use super::lifting::{gauss3_points, BoundaryData, DataValues};
use super::quadrature::{GAUSS2, GAUSS3};
use super::space::{jump_terms_with, CrSpace, Element};
use crate::mesh::Mesh;

/// The audit's forms on one mesh. Only the stabilised edges and the data points are stored (about 8
/// bytes an edge): the element geometry and the jump terms are recomputed at each [`FullForm::apply`],
/// so the audit adds no mesh-sized memory to a run.
/// A Gauss point of a Dirichlet edge with data: 2ρμ ω_q and the basis values (edge, φ) there.
type DataPoint = (f64, [(usize, f64); 3]);

pub struct FullForm {
    /// The edges carrying the jump term (interior and Dirichlet).
    stabilised: Vec<usize>,
    /// Per Dirichlet edge with data, per 3-point Gauss point: 2ρμ ω_q and the basis values of the
    /// edge's triangle there (edge, φ).
    data_points: Vec<[DataPoint; 3]>,
    pen: f64,
    law: Elasticity,
}

impl FullForm {
    /// The forms on `mesh` with the space's stabilised edges and the Dirichlet edges of `data`.
    pub fn new(mesh: &Mesh, space: &CrSpace, data: Option<&BoundaryData>, law: &Elasticity, rho: f64) -> FullForm {
        let pen = 2.0 * rho * law.mu;
        let stabilised = (0..mesh.edges.len()).filter(|&e| space.is_stabilised(mesh, e)).collect();
        let mut data_points = Vec::new();
        if let Some(data) = data {
            for &e in &data.dirichlet {
                let t = mesh.edge_tris[e].0;
                let (te, el) = (mesh.tri_edges[t], Element::new(mesh, t));
                let pts = gauss3_points(mesh, e);
                data_points.push([0, 1, 2].map(|q| {
                    let phi = Element::phi(el.bary(pts[q]));
                    (pen * GAUSS3[q].1, [0, 1, 2].map(|i| (te[i], phi[i])))
                }));
            }
        }
        FullForm { stabilised, data_points, pen, law: *law }
    }

    /// A U on `mesh` (the form's): the vector with A(U, V) = Σ_e (A U)_e·V_e.
    pub fn apply(&self, mesh: &Mesh, u: &[[f64; 2]]) -> Vec<[f64; 2]> {
        let mut y = vec![[0.0; 2]; u.len()];
        for (t, te) in mesh.tri_edges.iter().enumerate() {
            let el = Element::new(mesh, t);
            let s = self.law.strain_stress(el.gradient(te.map(|e| u[e]))).stress;
            let (sxx, syy, sxy) = (s[0], s[1], s[3]);
            for (i, &e) in te.iter().enumerate() {
                let g = el.grad_phi(i);
                y[e][0] += el.area * (sxx * g[0] + sxy * g[1]);
                y[e][1] += el.area * (sxy * g[0] + syy * g[1]);
            }
        }
        for &e in &self.stabilised {
            for (s, w) in GAUSS2 {
                let (terms, n) = jump_terms_with(mesh, e, s, |t| Element::new(mesh, t));
                let terms = &terms[..n];
                let mut j = [0.0; 2];
                for &(f, p) in terms {
                    j = [j[0] + p * u[f][0], j[1] + p * u[f][1]];
                }
                for &(f, p) in terms {
                    y[f][0] += self.pen * w * p * j[0];
                    y[f][1] += self.pen * w * p * j[1];
                }
            }
        }
        y
    }

    /// B(p, ·) edge by edge, for Dirichlet data p (zero without data).
    pub fn data_vector(&self, p: &DataValues, n_edges: usize) -> Vec<[f64; 2]> {
        let mut y = vec![[0.0; 2]; n_edges];
        for (pts, vals) in self.data_points.iter().zip(&p.d) {
            for ((w, phis), v) in pts.iter().zip(vals) {
                for &(e, phi) in phis {
                    y[e][0] += w * phi * v[0];
                    y[e][1] += w * phi * v[1];
                }
            }
        }
        y
    }

    /// C(p, r) of two sets of Dirichlet data.
    pub fn data_data(&self, p: &DataValues, r: &DataValues) -> f64 {
        let mut c = 0.0;
        for (a, b) in p.d.iter().zip(&r.d) {
            for (q, (_, w)) in GAUSS3.iter().enumerate() {
                c += self.pen * w * (a[q][0] * b[q][0] + a[q][1] * b[q][1]);
            }
        }
        c
    }
}

/// Σ_e a_e·b_e.
pub fn dot2(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x[0] * y[0] + x[1] * y[1]).sum()
}

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
use super::lifting::{gauss3_points, DataValues};
use super::quadrature::{GAUSS2, GAUSS3};
use super::space::{jump_terms_with, CrSpace, Element};
use crate::mesh::Mesh;

/// The audit's forms on one mesh.
pub struct FullForm {
    elements: Vec<Element>,
    tri_edges: Vec<[usize; 3]>,
    /// Per stabilised edge and Gauss point q: 2ρμ ω_q, and its jump terms (edge, signed basis value)
    /// `terms[first[q]..first[q + 1]]`.
    weight: Vec<f64>,
    first: Vec<usize>,
    terms: Vec<(usize, f64)>,
    /// Per Dirichlet edge with data, per 3-point Gauss point: 2ρμ ω_q and the basis values of the
    /// edge's triangle there (edge, φ).
    data_points: Vec<[(f64, [(usize, f64); 3]); 3]>,
    pen: f64,
    law: Elasticity,
}

impl FullForm {
    pub fn new(mesh: &Mesh, space: &CrSpace, law: &Elasticity, rho: f64) -> FullForm {
        let pen = 2.0 * rho * law.mu;
        let elements: Vec<Element> = (0..mesh.tris.len()).map(|t| Element::new(mesh, t)).collect();
        let (mut weight, mut first, mut terms) = (Vec::new(), vec![0], Vec::new());
        for e in 0..mesh.edges.len() {
            if space.is_stabilised(mesh, e) {
                for (s, w) in GAUSS2 {
                    weight.push(pen * w);
                    terms.extend(jump_terms_with(mesh, e, s, |t| elements[t]).0.into_iter().take(jump_len(mesh, e)));
                    first.push(terms.len());
                }
            }
        }
        let mut data_points = Vec::new();
        if let Some(data) = &space.data {
            for &e in &data.dirichlet {
                let t = mesh.edge_tris[e].0;
                let te = mesh.tri_edges[t];
                let pts = gauss3_points(mesh, e);
                data_points.push([0, 1, 2].map(|q| {
                    let phi = Element::phi(elements[t].bary(pts[q]));
                    (pen * GAUSS3[q].1, [0, 1, 2].map(|i| (te[i], phi[i])))
                }));
            }
        }
        FullForm { elements, tri_edges: mesh.tri_edges.clone(), weight, first, terms, data_points, pen, law: *law }
    }

    /// A U: the vector with A(U, V) = Σ_e (A U)_e·V_e.
    pub fn apply(&self, u: &[[f64; 2]]) -> Vec<[f64; 2]> {
        let mut y = vec![[0.0; 2]; u.len()];
        for (el, te) in self.elements.iter().zip(&self.tri_edges) {
            let s = self.law.strain_stress(el.gradient(te.map(|e| u[e]))).stress;
            let (sxx, syy, sxy) = (s[0], s[1], s[3]);
            for (i, &e) in te.iter().enumerate() {
                let g = el.grad_phi(i);
                y[e][0] += el.area * (sxx * g[0] + sxy * g[1]);
                y[e][1] += el.area * (sxy * g[0] + syy * g[1]);
            }
        }
        for (w, at) in self.weight.iter().zip(self.first.windows(2)) {
            let terms = &self.terms[at[0]..at[1]];
            let mut j = [0.0; 2];
            for &(e, p) in terms {
                j = [j[0] + p * u[e][0], j[1] + p * u[e][1]];
            }
            for &(e, p) in terms {
                y[e][0] += w * p * j[0];
                y[e][1] += w * p * j[1];
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

/// The number of jump terms of edge e (3 per triangle of the edge).
fn jump_len(mesh: &Mesh, e: usize) -> usize {
    3 * (1 + usize::from(mesh.edge_tris[e].1.is_some()))
}

/// Σ_e a_e·b_e.
pub fn dot2(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x[0] * y[0] + x[1] * y[1]).sum()
}

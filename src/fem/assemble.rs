//! Assembly of the stabilised CR stiffness K on the unknowns of V_h, once per run.
//!
//! K_ij = a_h(ψ_j, ψ_i) with
//!   a_h(v, w) = Σ_T ∫_T σ(v):ε(w) + Σ_{e ∈ interior ∪ Dirichlet} (2ρμ/h_e) ∫_e [v]·[w],
//! the volume term from the one law ([`Elasticity::element_block`]), the jump [v] = v|T1 − v|T2 (v on a
//! Dirichlet edge) integrated by 2-point Gauss — exact, whereas a midpoint rule would see nothing
//! because the jump of two CR functions has zero mean on each edge.

use super::elasticity::Elasticity;
use super::quadrature::GAUSS2;
use super::space::{jump_terms, CrSpace, Element};
use crate::mesh::Mesh;
use crate::sparse::csc_from_triplets;
use faer::sparse::SparseColMat;

/// Add the coupling block between the midpoint values of edges a and b to the triplets:
/// K[k, l] += Σ_cd v_k[c] block[c][d] w_l[d] over the terms of both edges.
fn scatter(space: &CrSpace, a: usize, b: usize, block: [[f64; 2]; 2], trip: &mut Vec<(usize, usize, f64)>) {
    for (k, v) in space.edge_dof[a].terms() {
        for (l, w) in space.edge_dof[b].terms() {
            let val =
                v[0] * (block[0][0] * w[0] + block[0][1] * w[1]) + v[1] * (block[1][0] * w[0] + block[1][1] * w[1]);
            if val != 0.0 {
                trip.push((k, l, val));
            }
        }
    }
}

/// Assemble K (both triangles of the symmetric matrix stored).
pub fn stiffness(mesh: &Mesh, space: &CrSpace, law: &Elasticity, rho: f64) -> SparseColMat<usize, f64> {
    let mut trip = Vec::with_capacity(36 * mesh.tris.len() + 100 * mesh.edges.len());
    for t in 0..mesh.tris.len() {
        let el = Element::new(mesh, t);
        for i in 0..3 {
            for j in 0..3 {
                scatter(
                    space,
                    mesh.tri_edges[t][i],
                    mesh.tri_edges[t][j],
                    law.element_block(el.area, el.grad_phi(i), el.grad_phi(j)),
                    &mut trip,
                );
            }
        }
    }
    let pen = 2.0 * rho * law.mu;
    for e in 0..mesh.edges.len() {
        if !space.is_stabilised(mesh, e) {
            continue;
        }
        // (2ρμ/h_e) ∫_e [v]·[w] = 2ρμ Σ_q w_q [v](x_q)·[w](x_q)  (the weights sum to 1, ∫_e = h_e Σ_q w_q),
        // summed into the local matrix M_ab of the ≤ 6 basis functions of the two triangles first (the
        // shared edge's function appears on both sides and is merged) and scattered once.
        let mut idx: Vec<usize> = Vec::with_capacity(6);
        let mut m = [[0.0f64; 6]; 6];
        for (s, w) in GAUSS2 {
            let mut p = [0.0f64; 6];
            for (a, pa) in jump_terms(mesh, e, s) {
                let i = idx.iter().position(|&x| x == a).unwrap_or_else(|| {
                    idx.push(a);
                    idx.len() - 1
                });
                p[i] += pa;
            }
            for i in 0..idx.len() {
                for j in 0..idx.len() {
                    m[i][j] += pen * w * p[i] * p[j];
                }
            }
        }
        for (i, &a) in idx.iter().enumerate() {
            for (j, &b) in idx.iter().enumerate() {
                scatter(space, a, b, [[m[i][j], 0.0], [0.0, m[i][j]]], &mut trip);
            }
        }
    }
    csc_from_triplets(space.n_dofs, &trip)
}

//! The lowest-order Crouzeix–Raviart element and the discrete space V_h.
//!
//! On a triangle with barycentric coordinates λ_i, the basis function of the edge opposite vertex i is
//! φ_i = 1 − 2λ_i: it is 1 at that edge's midpoint and 0 at the other two, and ∇φ_i = −2∇λ_i is constant.
//! A vector CR function has one 2-vector per edge midpoint. In V_h the midpoint value is
//!
//! * `Fixed` (zero) on Dirichlet edges (u_D's edge mean, the lifting, is added outside V_h: `lifting`),
//! * s_e τ_e on contact edges (τ_e = (−n_y, n_x), n_e outward: the normal part is eliminated; an imposed
//!   normal displacement is part of the lifting), one unknown,
//! * s_e τ_e + r_e n_e on contact edges when the scene has normal unknowns (a unilateral or a Coulomb
//!   part, `scene::ContactPart::normal_unknown`): two unknowns, tangential then normal,
//! * (u_x, u_y) elsewhere, two unknowns.
//!
//! The interpolant I_CR takes edge means (3-point Gauss), which commute with time derivatives.
//!
//! ```
//! use tresca_cr::fem::quadrature::{edge_point, GAUSS3};
//! use tresca_cr::fem::space::Element;
//!
//! // φ_i = 1 − 2λ_i is 1 at the midpoint of the edge opposite vertex i and 0 at the other two
//! let mid0 = [0.0, 0.5, 0.5]; // the midpoint of the edge opposite vertex 0, in barycentric coordinates
//! assert_eq!(Element::phi(mid0), [1.0, 0.0, 0.0]);
//! // the edge mean of a function is 3-point Gauss on the edge: exact for degree 5 along it
//! let (a, b) = ([0.0, 0.0], [2.0, 0.0]);
//! let mean: f64 = GAUSS3.iter().map(|&(s, w)| w * edge_point(a, b, s)[0].powi(5)).sum();
//! assert!((mean - 32.0 / 6.0).abs() < 1e-13); // (1/2) ∫₀² x⁵ dx
//! ```

use super::quadrature::{edge_point, GAUSS3};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::{ExprSet, Vec2Expr};
use crate::scene::{ContactLaw, FrictionBound, Part, PartKind};

/// Geometry of one triangle: constant barycentric gradients.
#[derive(Clone, Copy, Debug)]
pub struct Element {
    pub pts: [[f64; 2]; 3],
    pub area: f64,
    /// ∇λ_i.
    pub grad_lambda: [[f64; 2]; 3],
}

impl Element {
    /// The element of triangle t.
    pub fn new(mesh: &Mesh, t: usize) -> Element {
        let pts = mesh.tris[t].map(|v| mesh.points[v]);
        let a2 = crate::mesh::area2(pts[0], pts[1], pts[2]);
        let mut grad_lambda = [[0.0; 2]; 3];
        for (i, g) in grad_lambda.iter_mut().enumerate() {
            let (b, c) = (pts[(i + 1) % 3], pts[(i + 2) % 3]);
            *g = [(b[1] - c[1]) / a2, (c[0] - b[0]) / a2];
        }
        Element { pts, area: 0.5 * a2, grad_lambda }
    }

    /// ∇φ_i = −2∇λ_i.
    pub fn grad_phi(&self, i: usize) -> [f64; 2] {
        [-2.0 * self.grad_lambda[i][0], -2.0 * self.grad_lambda[i][1]]
    }

    /// Barycentric coordinates of x.
    pub fn bary(&self, x: [f64; 2]) -> [f64; 3] {
        let mut l = [0.0; 3];
        for (i, li) in l.iter_mut().enumerate() {
            let b = self.pts[(i + 1) % 3];
            *li = (x[0] - b[0]) * self.grad_lambda[i][0] + (x[1] - b[1]) * self.grad_lambda[i][1];
        }
        l
    }

    /// φ_i at barycentric point l.
    pub fn phi(l: [f64; 3]) -> [f64; 3] {
        l.map(|li| 1.0 - 2.0 * li)
    }

    /// Constant gradient G[c][d] = ∂u_c/∂x_d of the CR field with midpoint values u_i on edge i.
    pub fn gradient(&self, u: [[f64; 2]; 3]) -> [[f64; 2]; 2] {
        let mut g = [[0.0; 2]; 2];
        for (i, ui) in u.iter().enumerate() {
            let gp = self.grad_phi(i);
            for c in 0..2 {
                for d in 0..2 {
                    g[c][d] += ui[c] * gp[d];
                }
            }
        }
        g
    }
}

/// How the midpoint value of one edge depends on the unknowns: Σ coef · u[dof].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EdgeDof {
    Fixed,
    Free([usize; 2]),
    Tangential {
        dof: usize,
        tau: [f64; 2],
    },
    /// A contact edge with a normal unknown: `dofs` = [tangential, normal] along (τ, n).
    Frame {
        dofs: [usize; 2],
        tau: [f64; 2],
        normal: [f64; 2],
    },
}

impl EdgeDof {
    /// The (dof, vector coefficient) pairs of this edge.
    pub fn terms(&self) -> impl Iterator<Item = (usize, [f64; 2])> {
        let t: [Option<(usize, [f64; 2])>; 2] = match *self {
            EdgeDof::Fixed => [None, None],
            EdgeDof::Free([a, b]) => [Some((a, [1.0, 0.0])), Some((b, [0.0, 1.0]))],
            EdgeDof::Tangential { dof, tau } => [Some((dof, tau)), None],
            EdgeDof::Frame { dofs: [a, b], tau, normal } => [Some((a, tau)), Some((b, normal))],
        };
        t.into_iter().flatten()
    }
}

/// One Γ_C edge: unknown, frame and friction weight.
#[derive(Clone, Debug)]
pub struct ContactEdge {
    pub edge: usize,
    pub dof: usize,
    pub normal: [f64; 2],
    pub tangent: [f64; 2],
    pub length: f64,
    /// ḡ_e, the mean of g_a over the edge (0 on a Coulomb edge).
    pub g_mean: f64,
    /// The normal unknown r_e = u·n_e(m_e) (scenes with normal unknowns).
    pub normal_dof: Option<usize>,
    /// True on a unilateral edge (u·n ≤ ḡ), false on a bilateral one (u·n = ḡ).
    pub unilateral: bool,
    /// F̄_e, the mean of Coulomb's coefficient over the edge (`None`: Tresca).
    pub coulomb: Option<f64>,
}

/// The discrete space V_h on a mesh with its boundary parts bound.
#[derive(Clone, Debug)]
pub struct CrSpace {
    pub edge_dof: Vec<EdgeDof>,
    /// Scene part of each boundary edge.
    pub edge_part: Vec<Option<usize>>,
    pub n_dofs: usize,
    pub contact: Vec<ContactEdge>,
    /// Number of Dirichlet edges.
    pub n_dirichlet: usize,
}

impl CrSpace {
    /// Number the unknowns: two per free edge, one per contact edge, none on Dirichlet edges.
    pub fn new(mesh: &Mesh, parts: &[Part]) -> Result<CrSpace> {
        let names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
        let edge_part = mesh.bind_parts(&names)?;
        let mut edge_dof = Vec::with_capacity(mesh.edges.len());
        let mut contact = Vec::new();
        let mut n = 0;
        let mut n_dirichlet = 0;
        for (e, part) in edge_part.iter().enumerate() {
            let kind = part.map(|p| &parts[p].kind);
            edge_dof.push(match kind {
                Some(PartKind::Dirichlet(_)) => {
                    n_dirichlet += 1;
                    EdgeDof::Fixed
                }
                Some(PartKind::Contact(c)) => {
                    let normal = mesh.outward_normal(e);
                    let tangent = [-normal[1], normal[0]];
                    let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
                    let mean = |g: &FrictionBound| -> Result<f64> {
                        let mut m = 0.0;
                        for (s, w) in GAUSS3 {
                            let x = edge_point(a, b, s);
                            m += w * g.at(x[0], x[1])?;
                        }
                        Ok(m)
                    };
                    let g_mean = c.tresca().map(mean).transpose()?.unwrap_or(0.0);
                    let coulomb = c.coulomb().map(mean).transpose()?;
                    let length = mesh.edge_length(e);
                    let unilateral = c.law == ContactLaw::Unilateral;
                    let normal_dof = c.normal_unknown.then_some(n + 1);
                    contact.push(ContactEdge {
                        edge: e,
                        dof: n,
                        normal,
                        tangent,
                        length,
                        g_mean,
                        normal_dof,
                        unilateral,
                        coulomb,
                    });
                    match normal_dof {
                        None => {
                            n += 1;
                            EdgeDof::Tangential { dof: n - 1, tau: tangent }
                        }
                        Some(r) => {
                            n += 2;
                            EdgeDof::Frame { dofs: [r - 1, r], tau: tangent, normal }
                        }
                    }
                }
                _ => {
                    n += 2;
                    EdgeDof::Free([n - 2, n - 1])
                }
            });
        }
        Ok(CrSpace { edge_dof, edge_part, n_dofs: n, contact, n_dirichlet })
    }

    /// The contact unknowns in the order of the condensed problem: the tangential unknown of every Γ_C
    /// edge, then the normal unknowns (empty without normal unknowns: the bilateral Tresca problem).
    pub fn contact_dofs(&self) -> Vec<usize> {
        let t = self.contact.iter().map(|c| c.dof);
        t.chain(self.contact.iter().filter_map(|c| c.normal_dof)).collect()
    }

    /// The Γ_C edges with a normal unknown, as indices into `contact` (in the order of their unknowns in
    /// [`CrSpace::contact_dofs`]).
    pub fn normal_edges(&self) -> Vec<usize> {
        (0..self.contact.len()).filter(|&j| self.contact[j].normal_dof.is_some()).collect()
    }

    /// True if edge e carries the stabilisation (interior or Dirichlet).
    pub fn is_stabilised(&self, mesh: &Mesh, e: usize) -> bool {
        mesh.edge_tris[e].1.is_some() || self.edge_dof[e] == EdgeDof::Fixed
    }

    /// The paper's DOF count: 2 · (edges − Dirichlet edges) (contact normal components included).
    pub fn paper_dofs(&self) -> usize {
        2 * (self.edge_dof.len() - self.n_dirichlet)
    }

    /// The unknowns of each edge that has any, as groups `first[g]..first[g + 1]` of consecutive unknowns
    /// (the numbering follows the edges): the vertices of the factor's ordering graph.
    pub fn unknown_groups(&self) -> Vec<usize> {
        let mut first: Vec<usize> = self.edge_dof.iter().filter_map(|d| d.terms().next().map(|(k, _)| k)).collect();
        first.push(self.n_dofs);
        first
    }

    /// Displacement at every edge midpoint from the unknowns.
    pub fn midpoint_values(&self, u: &[f64]) -> Vec<[f64; 2]> {
        let mut out = Vec::with_capacity(self.edge_dof.len());
        self.midpoint_values_into(u, &mut out);
        out
    }

    /// [`CrSpace::midpoint_values`] into `out` (its previous content replaced, its memory reused).
    pub fn midpoint_values_into(&self, u: &[f64], out: &mut Vec<[f64; 2]>) {
        out.clear();
        out.extend(
            self.edge_dof
                .iter()
                .map(|d| d.terms().fold([0.0; 2], |acc, (k, c)| [acc[0] + c[0] * u[k], acc[1] + c[1] * u[k]])),
        );
    }

    /// I_CR v: edge means by 3-point Gauss, restricted to V_h (tangential part on contact edges). The
    /// expressions are evaluated at all Gauss points in one batch (the same bits as point by point).
    pub fn interpolate(&self, mesh: &Mesh, v: &Vec2Expr, t: f64) -> Result<Vec<f64>> {
        let edges: Vec<usize> = (0..self.edge_dof.len()).filter(|&e| self.edge_dof[e] != EdgeDof::Fixed).collect();
        let points: Vec<[f64; 2]> = edges
            .iter()
            .flat_map(|&e| {
                let [a, b] = mesh.edges[e].map(|p| mesh.points[p]);
                GAUSS3.map(|(s, _)| edge_point(a, b, s))
            })
            .collect();
        let mut vals = Vec::new();
        ExprSet::new(&[&v.0[0], &v.0[1]]).eval(&points, t, &mut vals)?;
        let mut u = vec![0.0; self.n_dofs];
        for (&e, val) in edges.iter().zip(vals.chunks_exact(6)) {
            let mut mean = [0.0; 2];
            for (i, (_, w)) in GAUSS3.iter().enumerate() {
                mean = [mean[0] + w * val[2 * i], mean[1] + w * val[2 * i + 1]];
            }
            for (k, c) in self.edge_dof[e].terms() {
                u[k] = c[0] * mean[0] + c[1] * mean[1];
            }
        }
        Ok(u)
    }
}

/// The jump of the CR basis across edge e at parameter s: (edge, signed basis value) for both sides.
pub fn jump_terms(mesh: &Mesh, e: usize, s: f64) -> Vec<(usize, f64)> {
    let (terms, len) = jump_terms_with(mesh, e, s, |t| Element::new(mesh, t));
    terms[..len].to_vec()
}

/// [`jump_terms`] with the elements of the mesh's triangles given by `element` (made once for many
/// edges), as a fixed array and its length.
pub fn jump_terms_with(
    mesh: &Mesh,
    e: usize,
    s: f64,
    element: impl Fn(usize) -> Element,
) -> ([(usize, f64); 6], usize) {
    let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
    let x = edge_point(a, b, s);
    let (t1, t2) = mesh.edge_tris[e];
    let (mut out, mut len) = ([(0usize, 0.0f64); 6], 0);
    for (t, sign) in [(Some(t1), 1.0), (t2, -1.0)] {
        if let Some(t) = t {
            let phi = Element::phi(element(t).bary(x));
            for (&edge, p) in mesh.tri_edges[t].iter().zip(phi) {
                out[len] = (edge, sign * p);
                len += 1;
            }
        }
    }
    (out, len)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Element {
        let mesh = crate::mesh::Mesh::build(crate::mesh::RawMesh {
            source: "t".into(),
            points: vec![[0.3, -0.2], [2.0, 0.4], [0.7, 1.9]],
            tris: vec![[0, 1, 2]],
            tagged: vec![],
            tag_names: vec![],
        })
        .unwrap();
        Element::new(&mesh, 0)
    }

    #[test]
    fn basis_is_nodal_at_edge_midpoints() {
        let el = tri();
        for i in 0..3 {
            let (b, c) = (el.pts[(i + 1) % 3], el.pts[(i + 2) % 3]);
            let m = [0.5 * (b[0] + c[0]), 0.5 * (b[1] + c[1])];
            let phi = Element::phi(el.bary(m));
            for (j, p) in phi.iter().enumerate() {
                assert!((p - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14, "φ_{j}(m_{i}) = {p}");
            }
        }
    }

    #[test]
    fn partition_of_unity_and_gradients_sum_to_zero() {
        let el = tri();
        for l in [[0.2, 0.3, 0.5], [1.0, 0.0, 0.0], [0.1, 0.8, 0.1]] {
            let s: f64 = Element::phi(l).iter().sum();
            assert!((s - 1.0).abs() < 1e-14);
        }
        let g: [f64; 2] = (0..3).fold([0.0; 2], |a, i| [a[0] + el.grad_phi(i)[0], a[1] + el.grad_phi(i)[1]]);
        assert!(g[0].abs() < 1e-13 && g[1].abs() < 1e-13);
    }

    #[test]
    fn gradients_match_finite_differences_of_the_basis() {
        let el = tri();
        let x = [0.9, 0.6];
        let h = 1e-6;
        for i in 0..3 {
            let f = |p: [f64; 2]| Element::phi(el.bary(p))[i];
            let gx = (f([x[0] + h, x[1]]) - f([x[0] - h, x[1]])) / (2.0 * h);
            let gy = (f([x[0], x[1] + h]) - f([x[0], x[1] - h])) / (2.0 * h);
            let g = el.grad_phi(i);
            assert!((gx - g[0]).abs() < 1e-8 && (gy - g[1]).abs() < 1e-8);
        }
    }
}

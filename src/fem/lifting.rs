//! Nonzero boundary data: u = u_D(x, y, t) on a dirichlet part, u·n = g_n(x, y, t) on a contact part
//! (scene keys `u` and `gap`, [`crate::scene::PartKind`]).
//!
//! **The lifting.** The discrete displacement is uⁿ = wⁿ + u_Lⁿ, w in V_h (the unknowns: zero at the
//! midpoints of Γ_D, tangential at those of Γ_C) and u_L the CR function whose midpoint values are
//!   u_L(m_e) = ū_D,e = (1/|e|) ∫_e u_D(·, tₙ)   on a Dirichlet edge,   u_L(m_e) = ḡ_e n_e   on a Γ_C edge,
//! ḡ_e = (1/|e|) ∫_e g_n(·, tₙ), and zero elsewhere: I_CR of the data, as the paper's I_CR takes edge means.
//! Every mean is taken by 3-point Gauss on the edge (degree 5: exact for data of degree ≤ 5 along the
//! edge; for smooth data its error O(h⁶) is far below the method's).
//!
//! **The stabilisation.** On a Dirichlet edge the jump is measured against the data, [u_h] = u_h − u_D,
//! so a step minimises
//!   ½ Σ_T ∫_T σ(u):ε(u) + ½ Σ_{e interior} (2ρμ/h_e) ∫_e |[u]|² + ½ Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e |u − u_D|²
//!   − (lⁿ, u) + j_h(u − uⁿ⁻¹)
//! over u = w + u_Lⁿ. With a_h the paper's form (Dirichlet jump = trace, the matrix K on V_h), its
//! stationarity in w is
//!   a_h(w, v) + j-term = (lⁿ, v) + b_D(tₙ; v) − a_h(u_Lⁿ, v)   for all v in V_h,
//!   b_D(t; v) = Σ_{e ⊂ Γ_D} 2ρμ Σ_q ω_q u_D(x_q, t)·v(x_q)   (3-point Gauss, ω_q summing to 1),
//! so the lifting enters the right-hand side through both parts of a_h: the elasticity term and the jump
//! term of every edge of a triangle with a lifted edge ([`LiftRhs`], added to the loads by `fem::loads`).
//! The friction problem on Γ_C is unchanged (the lifting is normal to Γ_C there).
//!
//! Scenes without data build none of this ([`BoundaryData::new`] returns `None`): bit-identical runs.

pub mod consistency;

use super::elasticity::Elasticity;
use super::quadrature::{edge_point, GAUSS2, GAUSS3};
use super::space::{jump_terms, ContactEdge, CrSpace, EdgeDof, Element};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::{BoundSet, ExprSet};
use crate::scene::{Part, PartKind};

/// The data u_D and g_n of a run bound to the 3-point Gauss points of their edges.
#[derive(Clone, Debug)]
pub struct BoundaryData {
    /// Dirichlet edges with data, part by part, each part's edges increasing.
    pub dirichlet: Vec<usize>,
    /// u_D of each such part bound to the points of its edges (3 per edge, edge by edge).
    d_sets: Vec<BoundSet>,
    /// Γ_C edges with an imposed normal displacement, as indices into `CrSpace::contact`.
    pub gap: Vec<usize>,
    /// g_n of each such part bound to the points of its edges.
    g_sets: Vec<BoundSet>,
}

/// The data at one time: u_D at the points of the Dirichlet edges (`d[i][q]`) and g_n at those of the
/// Γ_C edges (`g[j][q]`), in the order of [`BoundaryData`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DataValues {
    pub d: Vec<[[f64; 2]; 3]>,
    pub g: Vec<[f64; 3]>,
}

impl DataValues {
    /// All values in one vector: u_D (edge, point, component), then g_n (edge, point).
    pub fn flat(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.d.iter().flat_map(|e| e.iter().flatten().copied()).collect();
        v.extend(self.g.iter().flatten());
        v
    }

    /// self − other.
    pub fn minus(&self, o: &DataValues) -> DataValues {
        let sub2 = |a: [f64; 2], b: [f64; 2]| [a[0] - b[0], a[1] - b[1]];
        DataValues {
            d: self.d.iter().zip(&o.d).map(|(a, b)| [0, 1, 2].map(|q| sub2(a[q], b[q]))).collect(),
            g: self.g.iter().zip(&o.g).map(|(a, b)| [0, 1, 2].map(|q| a[q] - b[q])).collect(),
        }
    }
}

/// The 3-point Gauss points of edge e.
pub fn gauss3_points(mesh: &Mesh, e: usize) -> [[f64; 2]; 3] {
    let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
    GAUSS3.map(|(s, _)| edge_point(a, b, s))
}

/// Σ_q ω_q v_q, the 3-point Gauss mean.
pub fn mean3<const K: usize>(v: &[[f64; K]; 3]) -> [f64; K] {
    let mut m = [0.0; K];
    for (vq, (_, w)) in v.iter().zip(GAUSS3) {
        for (mc, x) in m.iter_mut().zip(vq) {
            *mc += w * x;
        }
    }
    m
}

/// The displacement u = w + u_L(t) at every edge midpoint: [`CrSpace::midpoint_values_into`] of the
/// unknowns `w` plus the lifting of the boundary data at time t (none without `data`).
pub fn displacement_into(
    space: &CrSpace,
    data: Option<&BoundaryData>,
    w: &[f64],
    t: f64,
    out: &mut Vec<[f64; 2]>,
) -> Result<()> {
    space.midpoint_values_into(w, out);
    if let Some(data) = data {
        let v = data.values(t)?;
        data.add_lifting(&space.contact, &v, out);
    }
    Ok(())
}

/// [`displacement_into`] into a new vector.
pub fn displacement(space: &CrSpace, data: Option<&BoundaryData>, w: &[f64], t: f64) -> Result<Vec<[f64; 2]>> {
    let mut out = Vec::with_capacity(space.edge_dof.len());
    displacement_into(space, data, w, t, &mut out)?;
    Ok(out)
}

impl BoundaryData {
    /// The data of `parts` on the space's mesh ([`BoundaryData::new`] with the space's parts and Γ_C edges).
    pub fn of(mesh: &Mesh, parts: &[Part], space: &CrSpace) -> Option<BoundaryData> {
        BoundaryData::new(mesh, parts, &space.edge_part, &space.contact)
    }

    /// The data of `parts` on the mesh (`edge_part`: the part of each boundary edge, `contact`: the Γ_C
    /// edges of the space); `None` when no part gives nonzero data.
    pub fn new(
        mesh: &Mesh,
        parts: &[Part],
        edge_part: &[Option<usize>],
        contact: &[ContactEdge],
    ) -> Option<BoundaryData> {
        if !parts.iter().any(|p| p.kind.has_data()) {
            return None;
        }
        let mut data = BoundaryData { dirichlet: Vec::new(), d_sets: Vec::new(), gap: Vec::new(), g_sets: Vec::new() };
        for (p, part) in parts.iter().enumerate() {
            match &part.kind {
                PartKind::Dirichlet(Some(u)) => {
                    let edges: Vec<usize> = (0..mesh.edges.len()).filter(|&e| edge_part[e] == Some(p)).collect();
                    let points = edges.iter().flat_map(|&e| gauss3_points(mesh, e)).collect();
                    data.d_sets.push(ExprSet::new(&[&u.0[0], &u.0[1]]).bind(points));
                    data.dirichlet.extend(edges);
                }
                PartKind::Contact(c) if c.lifted_gap().is_some() => {
                    let g = c.lifted_gap().expect("checked");
                    let idx: Vec<usize> =
                        (0..contact.len()).filter(|&j| edge_part[contact[j].edge] == Some(p)).collect();
                    let points = idx.iter().flat_map(|&j| gauss3_points(mesh, contact[j].edge)).collect();
                    data.g_sets.push(ExprSet::new(&[g]).bind(points));
                    data.gap.extend(idx);
                }
                _ => {}
            }
        }
        Some(data)
    }

    /// u_D and g_n at time t (an error naming the expression if a value is not finite).
    pub fn values(&self, t: f64) -> Result<DataValues> {
        let mut out = DataValues::default();
        let mut buf = Vec::new();
        for set in &self.d_sets {
            set.eval(t, &mut buf)?;
            out.d.extend(buf.chunks_exact(6).map(|c| [[c[0], c[1]], [c[2], c[3]], [c[4], c[5]]]));
        }
        for set in &self.g_sets {
            set.eval(t, &mut buf)?;
            out.g.extend(buf.chunks_exact(3).map(|c| [c[0], c[1], c[2]]));
        }
        Ok(out)
    }

    /// Add the lifting u_L (edge means of the data `v`) to the midpoint values `mid`.
    pub fn add_lifting(&self, contact: &[ContactEdge], v: &DataValues, mid: &mut [[f64; 2]]) {
        for (&e, d) in self.dirichlet.iter().zip(&v.d) {
            let m = mean3(d);
            mid[e] = [mid[e][0] + m[0], mid[e][1] + m[1]];
        }
        for (&j, g) in self.gap.iter().zip(&v.g) {
            let (e, n) = (contact[j].edge, contact[j].normal);
            let m = mean3(&g.map(|x| [x]))[0];
            mid[e] = [mid[e][0] + m * n[0], mid[e][1] + m * n[1]];
        }
    }

    /// The constrained components of the full midpoint field, each as (edge, unit vector): both axes
    /// of every Dirichlet edge with data, then the normal of every Γ_C edge with a gap.
    pub fn constrained(&self, contact: &[ContactEdge]) -> Vec<(usize, [f64; 2])> {
        let mut c: Vec<(usize, [f64; 2])> =
            self.dirichlet.iter().flat_map(|&e| [(e, [1.0, 0.0]), (e, [0.0, 1.0])]).collect();
        c.extend(self.gap.iter().map(|&j| (contact[j].edge, contact[j].normal)));
        c
    }
}

/// The lifting's right-hand side on the unknowns, b_D(t; ψ_k) − a_h(u_L(t), ψ_k), as a linear map of
/// the data values ([`DataValues::flat`]): entries (unknown k, value index, coefficient).
#[derive(Clone, Debug)]
pub struct LiftRhs {
    entries: Vec<(usize, usize, f64)>,
}

impl LiftRhs {
    pub fn new(
        mesh: &Mesh,
        edge_dof: &[EdgeDof],
        contact: &[ContactEdge],
        data: &BoundaryData,
        law: &Elasticity,
        rho: f64,
    ) -> LiftRhs {
        let pen = 2.0 * rho * law.mu;
        let mut entries = Vec::new();
        for (i, &c) in data.dirichlet.iter().enumerate() {
            for d in 0..2 {
                let mut dir = [0.0; 2];
                dir[d] = 1.0;
                for (k, a) in lifted_column(mesh, edge_dof, law, pen, c, dir) {
                    for (q, (_, w)) in GAUSS3.iter().enumerate() {
                        entries.push((k, 6 * i + 2 * q + d, -w * a));
                    }
                }
            }
            // b_D: 2ρμ Σ_q ω_q u_D(x_q)·v(x_q) for the unknowns v of the edge's triangle
            let t = mesh.edge_tris[c].0;
            let el = Element::new(mesh, t);
            for (q, (x, (_, w))) in gauss3_points(mesh, c).into_iter().zip(GAUSS3).enumerate() {
                let phi = Element::phi(el.bary(x));
                for (a, p) in mesh.tri_edges[t].iter().zip(phi) {
                    for (k, cv) in edge_dof[*a].terms() {
                        for (d, cd) in cv.into_iter().enumerate() {
                            if cd != 0.0 {
                                entries.push((k, 6 * i + 2 * q + d, pen * w * p * cd));
                            }
                        }
                    }
                }
            }
        }
        let off = 6 * data.dirichlet.len();
        for (j, &jc) in data.gap.iter().enumerate() {
            let c = &contact[jc];
            for (k, a) in lifted_column(mesh, edge_dof, law, pen, c.edge, c.normal) {
                for (q, (_, w)) in GAUSS3.iter().enumerate() {
                    entries.push((k, off + 3 * j + q, -w * a));
                }
            }
        }
        LiftRhs { entries }
    }

    /// out[slot[k]] += the right-hand side of the data values `v` ([`DataValues::flat`]).
    pub fn add(&self, v: &[f64], slot: &[usize], out: &mut [f64]) {
        for &(k, i, c) in &self.entries {
            out[slot[k]] += c * v[i];
        }
    }

    /// The unknowns the right-hand side can touch.
    pub fn unknowns(&self) -> impl Iterator<Item = usize> + '_ {
        self.entries.iter().map(|e| e.0)
    }
}

/// a_h(ψ_c dir, ψ_k) for every unknown k it couples to (with repeats): the elasticity term on the
/// triangle of boundary edge c and the jump terms (2-point Gauss, as in K) of its stabilised edges.
fn lifted_column(
    mesh: &Mesh,
    edge_dof: &[EdgeDof],
    law: &Elasticity,
    pen: f64,
    c: usize,
    dir: [f64; 2],
) -> Vec<(usize, f64)> {
    let t = mesh.edge_tris[c].0;
    let el = Element::new(mesh, t);
    let ic = mesh.tri_edges[t].iter().position(|&e| e == c).expect("an edge of its triangle");
    let mut out = Vec::new();
    for (j, &b) in mesh.tri_edges[t].iter().enumerate() {
        let m = law.element_block(el.area, el.grad_phi(ic), el.grad_phi(j));
        for (k, cv) in edge_dof[b].terms() {
            let v = (0..2).map(|x| (0..2).map(|y| dir[x] * m[x][y] * cv[y]).sum::<f64>()).sum();
            out.push((k, v));
        }
    }
    for &f in &mesh.tri_edges[t] {
        let stabilised = mesh.edge_tris[f].1.is_some() || edge_dof[f] == EdgeDof::Fixed;
        if !stabilised {
            continue;
        }
        for (s, w) in GAUSS2 {
            let terms = jump_terms(mesh, f, s);
            let pc: f64 = terms.iter().filter(|(e, _)| *e == c).map(|(_, p)| p).sum();
            for &(b, pb) in &terms {
                for (k, cv) in edge_dof[b].terms() {
                    out.push((k, pen * w * pc * pb * (dir[0] * cv[0] + dir[1] * cv[1])));
                }
            }
        }
    }
    out
}

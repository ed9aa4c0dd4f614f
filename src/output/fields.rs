//! Visualisation fields of one step, for two datasets: the **body** (the T triangles on the broken mesh)
//! and the **contact line** Γ_C (its C edges as line cells). Each carries only the fields that exist on it.
//!
//! The broken mesh has 3 points per triangle (point 3t + j is local vertex j of triangle t), so the CR
//! field is written exactly as a discontinuous P1 field: on T, u_h|_T = Σ_i φ_i U_{e_i} with
//! φ_i = 1 − 2λ_i, hence at local vertex j (λ_j = 1): u_h|_T(v_j) = Σ_{i≠j} U_{e_i} − U_{e_j}.
//! Warped by this field, neighbouring triangles separate: the CR field is continuous only at edge
//! midpoints, so the gaps are the method's nonconformity, not an error of the picture.
//! Contact edge k has its own two points 2k, 2k + 1: the broken points of its one triangle, with that
//! triangle's displacement there, so the line moves with the body.
//!
//! Body cell arrays (constant on a triangle):
//! * `strain`: symmetric tensor in VTK's 6-component order (xx, yy, zz, xy, yz, xz); ε_zz = ε_yz = ε_xz = 0,
//!   ε_xy is the tensor (not engineering) shear strain;
//! * `stress`: same order, plane strain: σ = λ tr ε I + 2μ ε, σ_zz = λ tr ε;
//! * `von_mises`: √(½[(σxx−σyy)² + (σyy−σzz)² + (σzz−σxx)²] + 3σxy²).
//!
//! Contact cell arrays: `sigma_t` = σ_τ·τ_e = −μ_e/|e|, `slip` = u_τ(m_e),
//! `slip_increment` = sⁿ − sⁿ⁻¹ (0 at step 0), `stick_slip` = 0 stick, 1 slip; with normal unknowns
//! also `pressure` p_e = P_e/|e|, `gap` u·n(m_e) − ḡ_e and `status` (0 stick, 1 slip, 2 separated).

use super::Run;
use crate::fem::elasticity::{von_mises, Elasticity};
use crate::fem::space::Element;
use crate::stepping::StepResult;

/// Components of the strain and stress arrays.
pub const TENSOR: usize = 6;

/// Static geometry of both datasets and what a step needs to evaluate fields fast.
pub struct Fields {
    /// Broken body points (3T, 3), z = 0.
    pub points: Vec<[f64; 3]>,
    /// Contact line points (2C, 3): point 2k + i is broken point `contact_points_of[2k + i]` of the body.
    pub contact_points: Vec<[f64; 3]>,
    contact_points_of: Vec<usize>,
    /// tri_edges of every triangle.
    tri_edges: Vec<[usize; 3]>,
    /// Element geometry of every triangle.
    elements: Vec<Element>,
    /// |e| of each contact edge.
    contact_len: Vec<f64>,
    law: Elasticity,
}

/// One step's arrays (f32, as written): body point and cell arrays, then contact point and cell arrays.
#[derive(Default)]
pub struct StepFields {
    pub displacement: Vec<f32>,
    pub strain: Vec<f32>,
    pub stress: Vec<f32>,
    pub von_mises: Vec<f32>,
    pub contact_displacement: Vec<f32>,
    pub sigma_t: Vec<f32>,
    pub slip: Vec<f32>,
    pub slip_increment: Vec<f32>,
    pub stick_slip: Vec<u8>,
    /// The normal condition (empty without normal unknowns).
    pub pressure: Vec<f32>,
    pub gap: Vec<f32>,
    pub status: Vec<u8>,
}

impl Fields {
    pub fn new(p: &Run) -> Fields {
        let (mesh, space) = (p.mesh, p.space);
        let nt = mesh.tris.len();
        let nc = space.contact.len();
        let mut points = Vec::with_capacity(3 * nt);
        let mut elements = Vec::with_capacity(nt);
        for (t, tri) in mesh.tris.iter().enumerate() {
            for &v in tri {
                let x = mesh.points[v];
                points.push([x[0], x[1], 0.0]);
            }
            elements.push(Element::new(mesh, t));
        }
        let mut contact_points_of = Vec::with_capacity(2 * nc);
        let mut contact_len = Vec::with_capacity(nc);
        for c in &space.contact {
            let t = mesh.edge_tris[c.edge].0;
            let i =
                mesh.tri_edges[t].iter().position(|&e| e == c.edge).expect("contact edge is an edge of its triangle");
            contact_points_of.extend([3 * t + (i + 1) % 3, 3 * t + (i + 2) % 3]);
            contact_len.push(c.length);
        }
        Fields {
            contact_points: contact_points_of.iter().map(|&q| points[q]).collect(),
            points,
            contact_points_of,
            tri_edges: mesh.tri_edges.clone(),
            elements,
            contact_len,
            law: p.law,
        }
    }

    /// Body points (3T).
    pub fn n_points(&self) -> usize {
        self.points.len()
    }
    /// Triangles T.
    pub fn n_tris(&self) -> usize {
        self.tri_edges.len()
    }
    /// Contact edges C.
    pub fn n_contact(&self) -> usize {
        self.contact_len.len()
    }

    /// |e| of each contact edge.
    pub fn contact_lengths(&self) -> &[f64] {
        &self.contact_len
    }

    /// Evaluate every array of a step into `out` (buffers are reused). `mid` are the midpoint values,
    /// `prev_slip` the previous step's slip (None at step 0).
    pub fn eval(&self, mid: &[[f64; 2]], r: &StepResult, prev_slip: Option<&[f64]>, out: &mut StepFields) {
        let nt = self.n_tris();
        let nc = self.n_contact();
        // every entry is written below: the buffers are only sized (no pushes in the loop)
        out.displacement.resize(9 * nt, 0.0);
        out.strain.resize(TENSOR * nt, 0.0);
        out.stress.resize(TENSOR * nt, 0.0);
        out.von_mises.resize(nt, 0.0);
        let cells =
            out.strain.chunks_exact_mut(TENSOR).zip(out.stress.chunks_exact_mut(TENSOR)).zip(&mut out.von_mises);
        let points = out.displacement.chunks_exact_mut(9);
        for (((te, el), d), ((strain, stress), vm)) in self.tri_edges.iter().zip(&self.elements).zip(points).zip(cells)
        {
            let u = te.map(|e| mid[e]);
            let s = [u[0][0] + u[1][0] + u[2][0], u[0][1] + u[1][1] + u[2][1]];
            for (d, uj) in d.chunks_exact_mut(3).zip(&u) {
                d.copy_from_slice(&[(s[0] - 2.0 * uj[0]) as f32, (s[1] - 2.0 * uj[1]) as f32, 0.0]);
            }
            let ss = self.law.strain_stress(el.gradient(u));
            let ([exx, eyy, exy], [sxx, syy, szz, sxy]) = (ss.strain, ss.stress);
            strain.copy_from_slice(&[exx as f32, eyy as f32, 0.0, exy as f32, 0.0, 0.0]);
            stress.copy_from_slice(&[sxx as f32, syy as f32, szz as f32, sxy as f32, 0.0, 0.0]);
            *vm = von_mises(ss.stress) as f32;
        }
        out.contact_displacement.clear();
        for &q in &self.contact_points_of {
            out.contact_displacement.extend_from_slice(&out.displacement[3 * q..3 * q + 3]);
        }
        for v in [&mut out.sigma_t, &mut out.slip, &mut out.slip_increment] {
            v.clear();
        }
        out.stick_slip.clear();
        for k in 0..nc {
            out.sigma_t.push((-r.mu[k] / self.contact_len[k]) as f32);
            out.slip.push(r.slip[k] as f32);
            out.slip_increment.push(prev_slip.map_or(0.0, |p| r.slip[k] - p[k]) as f32);
            out.stick_slip.push(r.state[k] as u8);
        }
        self.eval_normal(r, out);
    }

    /// The normal condition's arrays of `r` into `out` (left empty without normal unknowns).
    fn eval_normal(&self, r: &StepResult, out: &mut StepFields) {
        let n = &r.normal;
        out.pressure.clear();
        out.pressure.extend(n.force.iter().zip(&self.contact_len).map(|(p, l)| (p / l) as f32));
        out.gap.clear();
        out.gap.extend(n.gap.iter().map(|&g| g as f32));
        out.status.clear();
        out.status.extend(super::normal_series::status(r));
    }
}

//! Distances between the levels of a study, at the time nodes common to all levels.
//!
//! * consecutive error (the paper's): |||u_l − P u_{l−1}|||, the discrete energy norm a_h(·,·)^{1/2} of the
//!   finer level (P: [`Prolongation`]; its jumps on coarse edges are charged with the fine penalty);
//! * error against a finer reference run u_ref, the true error with u replaced by u_ref:
//!   |||u_ref − u_l|||² = Σ_{T ∈ reference mesh} ∫_T σ(u_ref − u_l):ε(u_ref − u_l) + Σ_{e ∈ E_l⁰} (2ρμ/h_e) ∫_e |[u_l]|²
//!   (u_l is linear on each reference triangle of nested meshes; the exact u has no jumps), or
//!   a_h(u_ref − u_l, u_ref − u_l)^{1/2} on a shared mesh (a time study against a semi-discrete reference);
//! * the distance of the Richardson model ([`super::richardson`]): on nested meshes the broken energy
//!   seminorm (Σ_{T fine} ∫_T σ(u_f − u_c):ε(u_f − u_c))^{1/2} — a true inner-product norm on the finest
//!   broken-P1 space, in which the level errors' gradient parts live, the jump part |||·|||² − that of a
//!   level's own error being its own jumps, computed exactly — and a_h(·,·)^{1/2} on a shared mesh.
//!
//! With boundary data (`fem::lifting`) every distance is one of the displacements u = w + u_L(tₙ), not of
//! the unknowns w, as the true errors are: the densities and the prolongation take the full midpoint
//! fields ([`Kept::displacement`]), the consecutive error is A(d, d)^{1/2} with d = u_l − P u_{l−1} and A
//! the audit's form on full fields (`fem::forms`: the jump of d on Γ_D is d), and a level's own jumps
//! are measured against u_D on Γ_D. On a shared mesh the lifting of the common nodes is the same on both
//! levels, so u_f − u_c = w_f − w_c there. Without data every quantity is computed as before, bit for bit.

use crate::error::Result;
use crate::fem::forms::{dot2, FullForm};
use crate::fem::norms::ErrorEvaluator;
use crate::fem::prolong::{parent_triangles, Prolongation};
use crate::fem::space::Element;
use crate::sparse::symmetric_energy;
use crate::stepping::Problem;

/// A finished run kept for comparisons: problem, and unknowns at the common time nodes `t`.
pub struct Kept {
    pub problem: Problem,
    pub u: Vec<Vec<f64>>,
    pub t: Vec<f64>,
}

impl Kept {
    /// The displacement u = w + u_L(t) at every edge midpoint at common node i (the unknowns' midpoint
    /// values without boundary data).
    pub fn displacement(&self, i: usize) -> Result<Vec<[f64; 2]>> {
        self.problem.displacement(&self.u[i], self.t[i])
    }

    fn has_data(&self) -> bool {
        self.problem.data.is_some()
    }
}

/// a_h(e, e)^{1/2} on the unknowns of `p`.
fn energy_norm(p: &Problem, e: &[f64]) -> f64 {
    symmetric_energy(&p.stiffness, e).max(0.0).sqrt()
}

fn same_mesh(a: &Kept, b: &Kept) -> bool {
    a.problem.scene.mesh_level() == b.problem.scene.mesh_level()
}

/// Two levels on nested meshes (`parent[t]`: the coarse triangle of fine triangle t; the same mesh with
/// t ↦ t), with the elements of both made once for the densities at many time nodes.
pub struct Pair<'a> {
    fine: &'a Problem,
    coarse: &'a Problem,
    parent: Vec<usize>,
    fine_elements: Vec<Element>,
    coarse_elements: Vec<Element>,
}

impl<'a> Pair<'a> {
    pub fn new(fine: &'a Problem, coarse: &'a Problem, parent: Vec<usize>) -> Pair<'a> {
        let elements = |p: &Problem| (0..p.mesh.tris.len()).map(|t| Element::new(&p.mesh, t)).collect();
        Pair { fine, coarse, parent, fine_elements: elements(fine), coarse_elements: elements(coarse) }
    }

    /// Elementwise energy density σ(u_f − u_c):ε(u_f − u_c) on the fine triangles for the midpoint fields
    /// `mf`, `mc` ([`Kept::displacement`]).
    pub fn density(&self, mf: &[[f64; 2]], mc: &[[f64; 2]]) -> Vec<f64> {
        let (fine, coarse) = (self.fine, self.coarse);
        // the gradient of each coarse triangle once, not once per child
        let coarse_gradient: Vec<[[f64; 2]; 2]> = (0..coarse.mesh.tris.len())
            .map(|pt| self.coarse_elements[pt].gradient(coarse.mesh.tri_edges[pt].map(|e| mc[e])))
            .collect();
        (0..fine.mesh.tris.len())
            .map(|t| {
                let gf = self.fine_elements[t].gradient(fine.mesh.tri_edges[t].map(|e| mf[e]));
                let gc = coarse_gradient[self.parent[t]];
                let d = [[gf[0][0] - gc[0][0], gf[0][1] - gc[0][1]], [gf[1][0] - gc[1][0], gf[1][1] - gc[1][1]]];
                fine.law.energy_density(d)
            })
            .collect()
    }
}

/// Σ_T |T| density_T.
fn integrate(p: &Problem, dens: &[f64]) -> f64 {
    dens.iter().enumerate().map(|(t, d)| p.mesh.area(t) * d).sum()
}

/// ‖u_fine − P u_coarse‖ (a_h of the finer level) at every common node.
pub fn consecutive(fine: &Kept, coarse: &Kept) -> Result<Vec<f64>> {
    let (c, f) = (&coarse.problem, &fine.problem);
    let p = Prolongation::new(&parent_triangles(&c.mesh, &f.mesh)?, &c.mesh, (&f.mesh, &f.space));
    if fine.has_data() {
        let form = FullForm::new(&f.mesh, &f.space, f.data.as_ref(), &f.law, f.scene.rho);
        return (0..fine.u.len())
            .map(|i| {
                let (mf, pc) = (fine.displacement(i)?, p.apply_full(&coarse.displacement(i)?));
                let d: Vec<[f64; 2]> = mf.iter().zip(&pc).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
                Ok(dot2(&form.apply(&f.mesh, &d), &d).max(0.0).sqrt())
            })
            .collect();
    }
    Ok(fine
        .u
        .iter()
        .zip(&coarse.u)
        .map(|(uf, uc)| {
            let pu = p.apply(&c.space, uc, &f.space);
            let d: Vec<f64> = uf.iter().zip(&pu).map(|(a, b)| a - b).collect();
            energy_norm(f, &d)
        })
        .collect())
}

/// The model distance between a finer and a coarser level at every common node (module doc).
pub fn distance(fine: &Kept, coarse: &Kept) -> Result<Vec<f64>> {
    let (fp, cp) = (&fine.problem, &coarse.problem);
    if same_mesh(fine, coarse) {
        return Ok(fine.u.iter().zip(&coarse.u).map(|(a, b)| energy_norm(fp, &diff(a, b))).collect());
    }
    let pair = Pair::new(fp, cp, parent_triangles(&cp.mesh, &fp.mesh)?);
    (0..fine.u.len())
        .map(|i| Ok(integrate(fp, &pair.density(&fine.displacement(i)?, &coarse.displacement(i)?)).max(0.0).sqrt()))
        .collect()
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// The stabilisation energy Σ_e (2ρμ/h_e) ∫_e |[u_l]|² of a level at every common node (with boundary
/// data the jump on Γ_D is u_l − u_D: the jump part of the level's true error).
pub fn jumps(lv: &Kept) -> Result<Vec<f64>> {
    let p = &lv.problem;
    let has_data = p.data.is_some();
    let ev = ErrorEvaluator::new(&p.mesh, &p.space, has_data, &p.law, p.scene.rho);
    (0..lv.u.len())
        .map(|i| ev.jump_energy_at(&lv.displacement(i)?, &p.space, has_data, &p.scene.parts, lv.t[i]))
        .collect()
}

/// |||u_ref − u_l||| at every common node (module doc).
pub fn reference_error(rf: &Kept, lv: &Kept) -> Result<Vec<f64>> {
    if same_mesh(rf, lv) {
        return distance(rf, lv);
    }
    let grad = distance(rf, lv)?;
    Ok(grad.iter().zip(jumps(lv)?).map(|(g, j)| (g * g + j).max(0.0).sqrt()).collect())
}

/// (max, last) of a series.
pub fn max_last(v: &[f64]) -> [f64; 2] {
    [v.iter().copied().fold(0.0, f64::max), v.last().copied().unwrap_or(0.0)]
}

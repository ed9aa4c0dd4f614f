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

use crate::error::Result;
use crate::fem::norms::ErrorEvaluator;
use crate::fem::prolong::{parent_triangles, Prolongation};
use crate::fem::space::Element;
use crate::sparse::energy;
use crate::stepping::Problem;

/// A finished run kept for comparisons: problem and unknowns at the common time nodes.
pub struct Kept {
    pub problem: Problem,
    pub u: Vec<Vec<f64>>,
}

/// a_h(e, e)^{1/2} on the unknowns of `p`.
fn energy_norm(p: &Problem, e: &[f64]) -> f64 {
    energy(&p.stiffness, e).max(0.0).sqrt()
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

    /// Elementwise energy density σ(u_f − u_c):ε(u_f − u_c) on the fine triangles for unknowns `uf`, `uc`.
    pub fn density(&self, uf: &[f64], uc: &[f64]) -> Vec<f64> {
        let (fine, coarse) = (self.fine, self.coarse);
        let (mf, mc) = (fine.space.midpoint_values(uf), coarse.space.midpoint_values(uc));
        (0..fine.mesh.tris.len())
            .map(|t| {
                let gf = self.fine_elements[t].gradient(fine.mesh.tri_edges[t].map(|e| mf[e]));
                let pt = self.parent[t];
                let gc = self.coarse_elements[pt].gradient(coarse.mesh.tri_edges[pt].map(|e| mc[e]));
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
    Ok(fine.u.iter().zip(&coarse.u).map(|(uf, uc)| integrate(fp, &pair.density(uf, uc)).max(0.0).sqrt()).collect())
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// The stabilisation energy Σ_e (2ρμ/h_e) ∫_e |[u_l]|² of a level at every common node.
pub fn jumps(lv: &Kept) -> Vec<f64> {
    let p = &lv.problem;
    let ev = ErrorEvaluator::new(&p.mesh, &p.space, &p.law, p.scene.rho);
    lv.u.iter().map(|u| ev.jump_energy(&p.space.midpoint_values(u))).collect()
}

/// |||u_ref − u_l||| at every common node (module doc).
pub fn reference_error(rf: &Kept, lv: &Kept) -> Result<Vec<f64>> {
    if same_mesh(rf, lv) {
        return distance(rf, lv);
    }
    let grad = distance(rf, lv)?;
    Ok(grad.iter().zip(jumps(lv)).map(|(g, j)| (g * g + j).max(0.0).sqrt()).collect())
}

/// (max, last) of a series.
pub fn max_last(v: &[f64]) -> [f64; 2] {
    [v.iter().copied().fold(0.0, f64::max), v.last().copied().unwrap_or(0.0)]
}

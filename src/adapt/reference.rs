//! Errors of adapted levels against a finer reference solution on a mesh nested in all of them.
//!
//! Newest-vertex bisection from one labelled mesh makes every triangle a node of its initial
//! triangle's binary tree; its *generation* is the number of bisections, log₂(|T₀|/|T|) (each halves
//! the area). On the structured meshes labelled by their hypotenuses, marking every triangle bisects
//! each exactly once (compatible bisection), so the uniform route's level g is "all triangles of
//! generation g". The [`overlay`] of a mesh A with generation G — A refined until no triangle is
//! younger than G — is then nested in A, in every mesh A refines, and in the uniform mesh of any
//! generation ≤ G: one reference for both routes' levels. The distance of a level to it is the
//! `study` reference error: |||u_ref − u_l|||² = Σ_{T ∈ ref} ∫_T σ(u_ref − u_l):ε(u_ref − u_l) +
//! Σ_{e ∈ E⁰_l} (2ρμ/h_e)‖[u_l]‖²_e (∇u_l is constant on each reference triangle of nested meshes), max
//! over the time nodes. With boundary data (`fem::lifting`) both levels are compared by their full
//! displacements w + u_L(t), and a Dirichlet edge's jump is u_l − u_D (the jump part of the true error,
//! as `study`'s reference error measures it).

use crate::error::Result;
use crate::fem::elasticity::Elasticity;
use crate::fem::lifting::{displacement, BoundaryData};
use crate::fem::norms::ErrorEvaluator;
use crate::fem::prolong::parent_triangles;
use crate::fem::space::{CrSpace, Element};
use crate::mesh::bisect::bisect;
use crate::mesh::Mesh;
use crate::scene::Part;

/// A level's mesh, space and unknowns at every time node (times `t`), kept for comparisons; `parts` are
/// the scene's boundary parts (u_D of the Dirichlet ones with data).
pub struct Kept {
    pub mesh: Mesh,
    pub space: CrSpace,
    pub data: Option<BoundaryData>,
    pub u: Vec<Vec<f64>>,
    pub t: Vec<f64>,
    pub parts: Vec<Part>,
}

/// Generation of every triangle given the area of its initial ancestor.
pub fn generations(mesh: &Mesh, root_area: &[f64]) -> Vec<u32> {
    (0..mesh.tris.len()).map(|t| (root_area[t] / mesh.area(t)).log2().round().max(0.0) as u32).collect()
}

/// `mesh` refined until every triangle has generation ≥ `g` (`root_area`: per triangle, the area of its
/// initial ancestor), with the new triangles' root areas.
pub fn overlay(mut mesh: Mesh, mut root_area: Vec<f64>, g: u32) -> Result<(Mesh, Vec<f64>)> {
    loop {
        let marked: Vec<bool> = generations(&mesh, &root_area).iter().map(|&k| k < g).collect();
        if !marked.contains(&true) {
            return Ok((mesh, root_area));
        }
        let (raw, parent) = bisect(&mesh, &marked);
        root_area = parent.iter().map(|&p| root_area[p]).collect();
        mesh = Mesh::build(raw)?;
    }
}

/// max over the time nodes of |||u_fine − u_coarse||| on nested meshes (module doc).
pub fn distance(fine: &Kept, coarse: &Kept, law: &Elasticity, rho: f64) -> Result<f64> {
    Ok(max_distance(&increments(fine, coarse, law, rho, false)?))
}

/// max over the time nodes of the distance √(G² + J_coarse) of [`increments`].
pub fn max_distance(parts: &[Increment]) -> f64 {
    parts.iter().fold(0.0f64, |m, p| m.max((p.gradient + p.coarse_jumps).max(0.0).sqrt()))
}

/// The parts of the distance of two nested levels at one time node (squared): the broken energy of the
/// gradient difference, the coarse level's jump energy (against u_D), and, when asked, the fine level's.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Increment {
    pub gradient: f64,
    pub coarse_jumps: f64,
    pub fine_jumps: f64,
}

/// [`Increment`] at every common time node; `fine_jumps` only with `with_fine` (else 0).
pub fn increments(fine: &Kept, coarse: &Kept, law: &Elasticity, rho: f64, with_fine: bool) -> Result<Vec<Increment>> {
    let parent = parent_triangles(&coarse.mesh, &fine.mesh)?;
    let fe: Vec<Element> = (0..fine.mesh.tris.len()).map(|t| Element::new(&fine.mesh, t)).collect();
    let ce: Vec<Element> = (0..coarse.mesh.tris.len()).map(|t| Element::new(&coarse.mesh, t)).collect();
    let has_data = coarse.data.is_some();
    let jumps = ErrorEvaluator::new(&coarse.mesh, &coarse.space, has_data, law, rho);
    let fine_eval = with_fine.then(|| ErrorEvaluator::new(&fine.mesh, &fine.space, has_data, law, rho));
    let mut out = Vec::with_capacity(fine.u.len());
    for (i, (uf, uc)) in fine.u.iter().zip(&coarse.u).enumerate() {
        let mf = displacement(&fine.space, fine.data.as_ref(), uf, fine.t[i])?;
        let mc = displacement(&coarse.space, coarse.data.as_ref(), uc, coarse.t[i])?;
        let coarse_jumps = jumps.jump_energy_at(&mc, &coarse.space, has_data, &coarse.parts, coarse.t[i])?;
        let fine_jumps = match &fine_eval {
            Some(f) => f.jump_energy_at(&mf, &fine.space, has_data, &fine.parts, fine.t[i])?,
            None => 0.0,
        };
        let mut gradient = 0.0;
        for (t, &p) in parent.iter().enumerate() {
            let gf = fe[t].gradient(fine.mesh.tri_edges[t].map(|e| mf[e]));
            let gc = ce[p].gradient(coarse.mesh.tri_edges[p].map(|e| mc[e]));
            let d = [[gf[0][0] - gc[0][0], gf[0][1] - gc[0][1]], [gf[1][0] - gc[1][0], gf[1][1] - gc[1][1]]];
            gradient += fine.mesh.area(t) * law.energy_density(d);
        }
        out.push(Increment { gradient, coarse_jumps, fine_jumps });
    }
    Ok(out)
}

//! The gap of the Γ_C edges that carry a normal unknown (`space::ContactEdge::normal_dof`): the edge
//! means ḡ_e(t) of g_n(x, y, t), by 3-point Gauss on the edge, the rule the lifting of a bilateral gap
//! uses (`fem::lifting`). With normal unknowns the gap is not lifted: it enters the condensed problem
//! (`friction`) as the offset of the normal condition, u_n(m_e) ≤ ḡ_e (unilateral) or = ḡ_e
//! (bilateral). Also the refusal of an initial state that penetrates, u₀·n > g(t₀) as edge means.

use super::lifting::{gauss3_points, mean3};
use super::space::CrSpace;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::scene::expr::{BoundSet, ExprSet};
use crate::scene::Scene;

/// Relative size of a penetration of the initial state below which it is taken as contact: 1e-9 of the
/// size of u₀·n and g there (rounding of u₀'s and g's edge means is ~1e-16 of them; a real
/// penetration below 1e-9 of the data is far below what the discretisation resolves).
const PENETRATION_TOL: f64 = 1e-9;

/// ḡ_e(t) of the normal unknowns, part by part.
#[derive(Clone, Debug)]
pub struct GapMeans {
    /// Per part with a nonzero gap: its expression bound to the Gauss points of its normal edges, and
    /// the positions of those edges among the normal unknowns.
    sets: Vec<(BoundSet, Vec<usize>)>,
    /// Number of normal unknowns.
    n: usize,
}

impl GapMeans {
    /// The gaps of `scene`'s contact parts on the normal unknowns of `space`.
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> GapMeans {
        let normal = space.normal_edges();
        let mut sets = Vec::new();
        for (p, part) in scene.parts.iter().enumerate() {
            let Some(g) = part.kind.contact().and_then(|c| c.gap.as_ref()) else { continue };
            let at: Vec<usize> =
                (0..normal.len()).filter(|&k| space.edge_part[space.contact[normal[k]].edge] == Some(p)).collect();
            let points = at.iter().flat_map(|&k| gauss3_points(mesh, space.contact[normal[k]].edge)).collect();
            sets.push((ExprSet::new(&[g]).bind(points), at));
        }
        GapMeans { sets, n: normal.len() }
    }

    /// ḡ_e(t) for every normal unknown (0 where a part gives no gap).
    pub fn at(&self, t: f64) -> Result<Vec<f64>> {
        let mut out = vec![0.0; self.n];
        let mut buf = Vec::new();
        for (set, at) in &self.sets {
            set.eval(t, &mut buf)?;
            for (&k, c) in at.iter().zip(buf.chunks_exact(3)) {
                out[k] = mean3(&[[c[0]], [c[1]], [c[2]]])[0];
            }
        }
        Ok(out)
    }
}

/// Refuse a scene whose initial state u⁰ = I_CR u₀ penetrates a unilateral part ([`check_initial`]),
/// before anything is assembled (nothing to check without normal unknowns or without u₀).
pub fn check_scene(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<()> {
    match &scene.u0 {
        Some(u0) if !space.normal_edges().is_empty() => {
            check_initial(scene, mesh, space, &space.interpolate(mesh, u0, scene.times[0])?)
        }
        _ => Ok(()),
    }
}

/// Refuse an initial state `u` (the unknowns of u⁰ = I_CR u₀) whose normal part exceeds the gap on a
/// unilateral edge, u⁰_n(m_e) > ḡ_e(t₀), naming the part and the edge's midpoint.
pub fn check_initial(scene: &Scene, mesh: &Mesh, space: &CrSpace, u: &[f64]) -> Result<()> {
    let normal = space.normal_edges();
    if normal.is_empty() {
        return Ok(());
    }
    let t0 = scene.times[0];
    let g = GapMeans::new(scene, mesh, space).at(t0)?;
    for (k, &j) in normal.iter().enumerate() {
        let c = &space.contact[j];
        let un = u[c.normal_dof.expect("a normal edge")];
        let tol = PENETRATION_TOL * un.abs().max(g[k].abs());
        if c.unilateral && un - g[k] > tol {
            let part = space.edge_part[c.edge].map_or("?", |p| scene.parts[p].name.as_str());
            let m = mesh.midpoint(c.edge);
            return Err(Error::scene(
                &scene.file,
                "initial.u0",
                format!(
                    "the initial state penetrates the unilateral part `{part}` at ({:.6}, {:.6}): u0·n = {un:e} > \
                     gap {:e} at t0 = {t0} (edge means)",
                    m[0], m[1], g[k]
                ),
            ));
        }
    }
    Ok(())
}

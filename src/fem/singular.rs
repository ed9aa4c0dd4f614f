//! The singular exponents of a scene: at every polygon corner and every boundary point where the condition
//! changes type, the leading exponent α of plane-strain elasticity ([`williams`](super::williams)), and
//! from the smallest, the energy-norm order that uniform refinement can reach, min(1, Re α) in h.
//!
//! A part's side conditions for the homogeneous problem: Dirichlet is clamped, Neumann free, and a contact
//! part may stick (clamped, the tangential motion held) or slip (sliding, u·n given and σ_τ = ±g_a, data
//! that do not change the exponent): its bound is the smaller of the two. Adaptive refinement that
//! resolves the singularities reaches N^(−1/2) in the number of unknowns N whatever α.
//!
//! **A floor, not a rate.** An exponent at most [`FLOOR_EXPONENT`] lowers the error by less than 2× over
//! every uniform refinement a scene allows (h^α over [`crate::scene::MAX_REFINE`] halvings: 2^{α·12} ≤ 2).
//! It arises where two sliding sides (contact that slips, symmetry) meet at an angle ω just below π,
//! α = π/ω − 1: the vertices of a polygonised curve (`docs/plan.md`, the slip paradox), whose singular
//! part carries an energy 2μc²αω R^{2α} within R of the vertex, all of it at scales no mesh resolves:
//! an error floor of about c√(2μαω) (c the tangential displacement there) that no refinement lowers.

use super::space::CrSpace;
use super::williams::{leading_exponent, Side};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::{Part, PartKind, Scene};
use nalgebra::Complex;

/// One boundary point with its leading exponent.
#[derive(Clone, Debug)]
pub struct Singularity {
    pub point: [f64; 2],
    /// Interior angle ω in (0, 2π].
    pub angle: f64,
    /// The parts of the two sides.
    pub parts: [usize; 2],
    /// The conditions of the pair that gives the smallest exponent.
    pub sides: [Side; 2],
    /// The leading exponent with 0 < Re α < 1, if there is one.
    pub alpha: Option<Complex<f64>>,
    /// The conditions of a contact side are the ones a run was seen in there ([`of_scene_observed`]),
    /// not the bound over stick and slip.
    pub observed: bool,
}

/// The exponent up to which a point gives an error floor rather than a rate (module doc): h^α falls by at
/// most 2× over [`crate::scene::MAX_REFINE`] halvings of h.
pub const FLOOR_EXPONENT: f64 = 1.0 / crate::scene::MAX_REFINE as f64;

impl Singularity {
    /// min(1, Re α): the energy-norm order in h that uniform refinement reaches near this point.
    pub fn uniform_order(&self) -> f64 {
        self.alpha.map_or(1.0, |a| a.re.min(1.0))
    }

    /// Whether the point gives an error floor, not a rate (Re α ≤ [`FLOOR_EXPONENT`], module doc).
    pub fn floor(&self) -> bool {
        self.uniform_order() <= FLOOR_EXPONENT
    }
}

/// The conditions a part can impose, for the homogeneous problem.
pub fn sides_of(kind: &PartKind) -> &'static [Side] {
    match kind {
        PartKind::Dirichlet(_) => &[Side::Clamped],
        PartKind::Neumann(_) => &[Side::Free],
        PartKind::Contact(_) => &[Side::Clamped, Side::Sliding],
    }
}

/// Every corner and change of condition of the mesh's boundary with its exponent; `edge_part` gives each
/// boundary edge's part (as `CrSpace::edge_part`).
pub fn singularities(mesh: &Mesh, edge_part: &[Option<usize>], parts: &[Part], nu: f64) -> Vec<Singularity> {
    singularities_observed(mesh, edge_part, parts, nu, |_| None)
}

/// [`singularities`] where `seen(point)` may give the conditions a contact side was in at that point (the
/// states a run went through there); a contact side without them takes the bound over stick and slip.
pub fn singularities_observed(
    mesh: &Mesh,
    edge_part: &[Option<usize>],
    parts: &[Part],
    nu: f64,
    seen: impl Fn([f64; 2]) -> Option<Vec<Side>>,
) -> Vec<Singularity> {
    let part = |e: usize| edge_part[e].expect("boundary edges belong to a part");
    let points = mesh.boundary_points(|a, b| sides_of(&parts[part(a)].kind) != sides_of(&parts[part(b)].kind));
    points
        .into_iter()
        .map(|p| {
            let pair = [part(p.edges[0]), part(p.edges[1])];
            let observed = pair.iter().any(|&q| matches!(parts[q].kind, PartKind::Contact(_))).then(|| seen(p.point));
            let observed = observed.flatten().filter(|s| !s.is_empty());
            let can = pair.map(|q| match (&parts[q].kind, &observed) {
                (PartKind::Contact(_), Some(s)) => s.clone(),
                (kind, _) => sides_of(kind).to_vec(),
            });
            let (sides, alpha) = worst([can[0].as_slice(), can[1].as_slice()], p.angle, nu);
            Singularity { point: p.point, angle: p.angle, parts: pair, sides, alpha, observed: observed.is_some() }
        })
        .collect()
}

/// The pair of conditions with the smallest exponent, over the conditions each side can be in.
fn worst(can: [&[Side]; 2], angle: f64, nu: f64) -> ([Side; 2], Option<Complex<f64>>) {
    let mut out = ([can[0][0], can[1][0]], None);
    for &a in can[0] {
        for &b in can[1] {
            let alpha = leading_exponent([a, b], angle, nu);
            if alpha.map_or(f64::INFINITY, |z| z.re) < out.1.map_or(f64::INFINITY, |z: Complex<f64>| z.re) {
                out = ([a, b], alpha);
            }
        }
    }
    out
}

/// min(1, min Re α) over the points: the energy-norm order in h of uniform refinement (1 without any).
pub fn uniform_order(points: &[Singularity]) -> f64 {
    points.iter().map(Singularity::uniform_order).fold(1.0, f64::min)
}

/// The singular points of a scene, found on its mesh before any refinement (refinement adds no corner and
/// no change of condition): what `check` lists, for the planner's order bound.
pub fn of_scene(scene: &Scene) -> Result<Vec<Singularity>> {
    of_scene_observed(scene, |_| None)
}

/// [`of_scene`] with the conditions contact sides were seen in ([`singularities_observed`]).
pub fn of_scene_observed(scene: &Scene, seen: impl Fn([f64; 2]) -> Option<Vec<Side>>) -> Result<Vec<Singularity>> {
    let mut s = scene.clone();
    s.set_refine(0)?;
    let mesh = Mesh::from_spec(&s.mesh)?;
    let space = CrSpace::new(&mesh, &s.parts)?;
    Ok(singularities_observed(&mesh, &space.edge_part, &s.parts, s.material.nu, seen))
}

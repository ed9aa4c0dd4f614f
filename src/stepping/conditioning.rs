//! The guard against a nearly singular stiffness matrix: a K whose condition-number estimate
//! (`solve::condition`) exceeds [`MAX_CONDITION`] is refused with the likeliest cause named.

use crate::error::{Error, Result};
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::Scene;

/// Largest accepted condition-number estimate of K: beyond it fewer than 4 of the 16 digits survive.
pub const MAX_CONDITION: f64 = 1e12;

/// Refuse the run when `kappa` (the estimate, a lower bound) is not below [`MAX_CONDITION`]: ρ → 0 (plain CR
/// fails Korn's inequality) or ν → ½ far beyond locking-free ranges factorise without complaint but give
/// meaningless displacements.
pub(super) fn check(kappa: f64, scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<()> {
    if kappa < MAX_CONDITION {
        return Ok(());
    }
    Err(Error::Linear(format!(
        "the stiffness matrix is too ill-conditioned (condition number ≳ {kappa:.1e} > {MAX_CONDITION:.0e}; \
         rho = {}, E = {}, nu = {}): results would keep fewer than 4 correct digits. Likely cause: {}",
        scene.rho,
        scene.material.e,
        scene.material.nu,
        ill_conditioning_cause(scene, mesh, space)
    )))
}

/// The likeliest reason for an ill-conditioned K, for its message: a piece of the body held by no
/// Dirichlet edge, slivers, a weak jump term, near-incompressibility.
fn ill_conditioning_cause(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> String {
    use crate::scene::PartKind;
    let dirichlet = |e: usize| space.edge_part[e].is_some_and(|p| matches!(scene.parts[p].kind, PartKind::Dirichlet));
    if let Some(p) = mesh.floating_piece(dirichlet) {
        return format!(
            "a piece of the mesh (through ({:e}, {:e})) shares no edge with the rest and has no Dirichlet edge: it \
             floats; connect it or clamp part of it",
            p[0], p[1]
        );
    }
    let (aspect, at) = mesh.worst_aspect();
    if aspect > 1e3 {
        return format!(
            "triangles of aspect ratio up to {aspect:.1e} (near ({:e}, {:e})); use better-shaped triangles",
            at[0], at[1]
        );
    }
    if scene.rho < 1.0 {
        return "rho < 1: use rho of order 1 or more (without the jump term CR fails Korn's inequality)".into();
    }
    if scene.material.nu > 0.49 {
        return "nu close to 1/2 (near-incompressible): lambda/mu is huge".into();
    }
    "none of a floating piece, slivers (aspect ratio > 1e3), rho < 1 or nu near 1/2: check the scale of E and \
     of the coordinates"
        .into()
}

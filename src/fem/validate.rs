//! The one validation of a scene that every command (`check`, `run` and its `--resume`, `study`, `plan`,
//! `adapt`) runs before any work, and that every set-up of a discretised problem runs again on its own
//! mesh and time grid (`stepping::Discretised::new`, the only way to one): what [`crate::Scene`]'s reading
//! cannot check alone because it needs the mesh.
//!
//! [`scene`] builds the scene's mesh at refine 0 (the level's edges are refinements of these; the
//! parts, their shared vertices and the data's consistency are properties of the data, not of the
//! level), binds the boundary parts to it ([`CrSpace::new`]: every boundary edge in one declared part,
//! every part with edges, g_a ≥ 0) and checks the boundary data ([`lifting::consistency::check`]: u₀
//! against u_D(t₀) and g_n(t₀), two Dirichlet parts at a shared vertex at every time node).

use super::lifting;
use super::space::CrSpace;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::Scene;

/// Validate `scene` on its coarsest mesh (module doc); an error names the part, point and values.
pub fn scene(scene: &Scene) -> Result<()> {
    let mut coarse = scene.clone();
    coarse.set_refine(0)?;
    let mesh = Mesh::from_spec(&coarse.mesh)?;
    on_mesh(scene, &mesh).map(|_| ())
}

/// The parts bound to `mesh` and the boundary data checked on it, at `scene`'s time nodes: the space.
pub fn on_mesh(scene: &Scene, mesh: &Mesh) -> Result<CrSpace> {
    let space = CrSpace::new(mesh, &scene.parts)?;
    lifting::consistency::check(scene, mesh, &space)?;
    Ok(space)
}

//! The one validation of a scene that every command (`check`, `run` and its `--resume`, `study`, `plan`,
//! `adapt`) runs before any work, and that every set-up of a discretised problem runs again on its own
//! mesh and time grid (`stepping::Discretised::new`, the only way to one): what [`crate::Scene`]'s reading
//! cannot check alone because it needs the mesh.
//!
//! [`scene`] builds the scene's mesh at refine 0 (the level's edges are refinements of these; the
//! parts, their shared vertices and the data's consistency are properties of the data, not of the
//! level), binds the boundary parts to it ([`CrSpace::new`]: every boundary edge in one declared part,
//! every part with edges, g_a ≥ 0) and checks the boundary data ([`lifting::consistency::check`]: u₀
//! against u_D(t₀) and g_n(t₀), two Dirichlet parts at a shared vertex at every time node), refuses
//! friction bounds whose forces cannot be multiplied ([`friction_forces`]) and an initial state that
//! penetrates a unilateral part ([`crate::fem::gap::check_scene`]).

use super::lifting;
use super::space::CrSpace;
use crate::error::{Error, Result};
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
    friction_forces(scene, mesh, &space)?;
    lifting::consistency::check(scene, mesh, &space)?;
    crate::fem::gap::check_scene(scene, mesh, &space)?;
    Ok(space)
}

/// Refuse a friction bound whose largest force on an edge, |e|·ḡ_e, lies beyond the square root of f64's
/// range (1.3e154), the rule of the material's stiffness entries (`scene::values`): the friction solver
/// forms squares of the forces (its residual norms) and the energy audit multiplies them by slip
/// increments and adds them to the work (g_a = 1e308 on an edge of length 2 gave |e|ḡ = inf and an audit
/// of inf and NaN). A bound that large is a bound that never binds: give the data in other units.
pub fn friction_forces(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<()> {
    let top = f64::MAX.sqrt();
    let Some(c) = space.contact.iter().find(|c| c.length * c.g_mean > top || (c.length * c.g_mean).is_nan()) else {
        return Ok(());
    };
    let part = space.edge_part[c.edge].map_or("?", |p| scene.parts[p].name.as_str());
    let x = mesh.midpoint(c.edge);
    Err(Error::scene(
        &scene.file,
        format!("boundary ({part}).g_a"),
        format!(
            "the friction force |e|·ḡ_e = {:.3e} of the edge at ({:.6}, {:.6}) (ḡ_e = {:.3e}) is beyond √(1.8e308) = \
             1.3e154: its square overflows f64, as its products with the slip may in the friction solver and the audit; \
             give the data in other units (u scales with load/E)",
            c.length * c.g_mean,
            x[0],
            x[1],
            c.g_mean
        ),
    ))
}

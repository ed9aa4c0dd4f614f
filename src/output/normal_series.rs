//! The series of the normal condition under `tresca/contact` (scenes with normal unknowns, a unilateral
//! or Coulomb part): `pressure` p_e = P_e/|e|, `gap` u·n(m_e) − ḡ_e (f64), `status` (u8: 0 stick,
//! 1 slip, 2 separated), and for `--resume` the exact unknowns a warm start needs: `force` P_e and
//! `normal_dof` (the edge's normal unknown), (·, C) each; and the static `coulomb` (C): F̄_e of a Coulomb
//! edge, NaN on a Tresca edge (the friction threshold is F̄_e P_e or ḡ_e); docs/results.md.

use super::h5::{put, Series};
use crate::fem::space::CrSpace;
use crate::stepping::StepResult;
use hdf5::Group;

/// Their names, in the order of the series.
pub const NORMAL: [&str; 5] = ["pressure", "gap", "status", "force", "normal_dof"];

/// Create them in `tresca` for `steps` steps (`None` without normal unknowns or without Γ_C).
pub fn create(tresca: &Group, space: &CrSpace, steps: usize) -> hdf5::Result<Option<[Series; 5]>> {
    let (false, Ok(cg)) = (space.normal_edges().is_empty(), tresca.group("contact")) else { return Ok(None) };
    let nc = space.contact.len();
    put(&cg, "coulomb", &[nc], &space.contact.iter().map(|c| c.coulomb.unwrap_or(f64::NAN)).collect::<Vec<_>>())?;
    let f = |k: usize| Series::create::<f64>(&cg, NORMAL[k], 1, &[nc], steps);
    Ok(Some([f(0)?, f(1)?, Series::create::<u8>(&cg, NORMAL[2], 1, &[nc], steps)?, f(3)?, f(4)?]))
}

/// Open them in `tresca` (`None` where a file has none, or not all: one written before `force` and
/// `normal_dof` were stored cannot be resumed).
pub fn open(tresca: &Group) -> Option<[Series; 5]> {
    let cg = tresca.group("contact").ok()?;
    let [a, b, c, d, e] = NORMAL.map(|k| Series::open(&cg, k, 1).ok());
    Some([a?, b?, c?, d?, e?])
}

/// The status of each Γ_C edge of `r` (0 stick, 1 slip, 2 separated; none without normal unknowns).
pub fn status(r: &StepResult) -> impl Iterator<Item = u8> + '_ {
    r.normal.separated.iter().zip(&r.state).map(|(&sep, &s)| if sep { 2 } else { s as u8 })
}

/// Read step n's normal state into `r` (force, gap, separated) and its normal unknowns into `r.u`.
pub fn read_into(s: &[Series; 5], space: &CrSpace, n: usize, r: &mut StepResult) -> hdf5::Result<()> {
    r.normal.force = s[3].read::<f64>(n)?;
    r.normal.gap = s[1].read::<f64>(n)?;
    r.normal.separated = s[2].read::<u8>(n)?.into_iter().map(|v| v == 2).collect();
    for (c, v) in space.contact.iter().zip(s[4].read::<f64>(n)?) {
        if let Some(k) = c.normal_dof {
            r.u[k] = v;
        }
    }
    Ok(())
}

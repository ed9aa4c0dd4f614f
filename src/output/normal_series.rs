//! The series of the normal condition under `tresca/contact` (scenes with normal unknowns, a unilateral
//! or Coulomb part): `pressure` p_e = P_e/|e|, `gap` u·n(m_e) − ḡ_e (f64) and `status` (u8: 0 stick,
//! 1 slip, 2 separated), (·, C) each; docs/results.md.

use super::h5::Series;
use crate::fem::space::CrSpace;
use crate::stepping::StepResult;
use hdf5::Group;

/// Their names, in the order of the series.
pub const NORMAL: [&str; 3] = ["pressure", "gap", "status"];

/// Create them in `tresca` for `steps` steps (`None` without normal unknowns or without Γ_C).
pub fn create(tresca: &Group, space: &CrSpace, steps: usize) -> hdf5::Result<Option<[Series; 3]>> {
    let (false, Ok(cg)) = (space.normal_edges().is_empty(), tresca.group("contact")) else { return Ok(None) };
    let nc = space.contact.len();
    Ok(Some([
        Series::create::<f64>(&cg, NORMAL[0], 1, &[nc], steps)?,
        Series::create::<f64>(&cg, NORMAL[1], 1, &[nc], steps)?,
        Series::create::<u8>(&cg, NORMAL[2], 1, &[nc], steps)?,
    ]))
}

/// Open them in `tresca` (`None` where a file has none).
pub fn open(tresca: &Group) -> Option<[Series; 3]> {
    let cg = tresca.group("contact").ok()?;
    let [a, b, c] = NORMAL.map(|k| Series::open(&cg, k, 1).ok());
    Some([a?, b?, c?])
}

/// The status of each Γ_C edge of `r` (0 stick, 1 slip, 2 separated; none without normal unknowns).
pub fn status(r: &StepResult) -> impl Iterator<Item = u8> + '_ {
    r.normal.separated.iter().zip(&r.state).map(|(&sep, &s)| if sep { 2 } else { s as u8 })
}

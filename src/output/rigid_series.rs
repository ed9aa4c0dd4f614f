//! The series `tresca/rigid` (·, k) of a floating body (no Dirichlet part, `solve::kernel`): α of every
//! step, the coefficients of the rigid motions in u = K⁺(l − Eλ) + Rα, exact, for the warm start of
//! `--resume` (the method of multipliers of `friction::floating` starts each step from the previous α,
//! and its answer depends on the start within the solver's tolerance). NaN where a step has no α (step 0,
//! the initial state). Not part of the step checksums, like the normal series (`super::normal_series`).

use super::h5::Series;
use crate::stepping::StepResult;
use hdf5::Group;

/// Its name under `/tresca`.
pub const RIGID: &str = "rigid";

/// Create it in `tresca` for `steps` steps and `k` rigid motions (`None` without rigid motions).
pub fn create(tresca: &Group, k: usize, steps: usize) -> hdf5::Result<Option<Series>> {
    if k == 0 {
        return Ok(None);
    }
    Series::create::<f64>(tresca, RIGID, 1, &[k], steps).map(Some)
}

/// Open it in `tresca` (`None` where a file has none: a body held by a Dirichlet part, or a file written
/// before α was stored, which cannot be resumed).
pub fn open(tresca: &Group) -> Option<Series> {
    Series::open(tresca, RIGID, 1).ok()
}

/// Step `r`'s row of width `k` appended to `out`: its α, or NaN when it has none.
pub fn push(out: &mut Vec<f64>, r: &StepResult, k: usize) {
    if r.rigid.len() == k {
        out.extend_from_slice(&r.rigid);
    } else {
        out.extend(std::iter::repeat_n(f64::NAN, k));
    }
}

/// Read step n's α into `r` (left empty where the row is NaN: a step without α).
pub fn read_into(s: &Series, n: usize, r: &mut StepResult) -> hdf5::Result<()> {
    let alpha = s.read::<f64>(n)?;
    r.rigid = if alpha.iter().any(|v| v.is_nan()) { vec![] } else { alpha };
    Ok(())
}

//! Taking a step into the writer's buffers: the checks that refuse a step with a value a results file
//! cannot hold (nothing of such a step is written), its rows of `/tresca` and, for a frame, its VTKHDF
//! fields.

use super::Writer;
use crate::error::{Error, Result};
use crate::fem::lifting::BoundaryData;
use crate::fem::space::CrSpace;
use crate::stepping::StepResult;
use std::path::Path;

/// An error naming the first non-finite value of `v`, if any.
fn check_finite(path: &Path, n: usize, what: &str, v: &[f64]) -> Result<()> {
    // one pass without early exit (vectorised) finds whether any value is not finite, the position is
    // looked for only then
    if v.iter().fold(true, |ok, x| ok & x.is_finite()) {
        return Ok(());
    }
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(k) => Err(Error::Io {
            path: path.to_path_buf(),
            msg: format!("step {n}: {what}[{k}] is not finite; the step was not written"),
        }),
    }
}

/// Refuse a frame whose displacement is not zero in f64 (`mid`, the midpoint values u(m_e)) but lies
/// wholly below f32's normal range (1.2e-38): the VTKHDF/XDMF views would show zeros, or a few subnormal
/// digits, where `/tresca` holds the answer (a scene scaled by 1e-300). The views' other fields are
/// derived from u; its largest value is what must survive the conversion.
fn underflows(path: &Path, n: usize, mid: &[[f64; 2]]) -> Result<()> {
    let largest = mid.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    if largest > 0.0 && largest < f32::MIN_POSITIVE as f64 {
        return Err(Error::Io {
            path: path.to_path_buf(),
            msg: format!(
                "step {n}: the displacement (largest |u| = {largest:.3e}) is below the single-precision range (1.2e-38) \
                 of the VTKHDF/XDMF views, which would show zeros; the step was not written (u is linear in the \
                 scene's data together, the loads, u₀, g_a and the parts' u and gap: scale them up)"
            ),
        });
    }
    Ok(())
}

/// The part of taking a step that needs only its unknowns and the space: the check of u, and the
/// midpoint values and contact unknowns written of it. [`Background`] evaluates it on the caller's
/// thread, beside the writer thread, and hands the writer this instead of u.
pub struct Unknowns {
    /// The step without u.
    r: StepResult,
    mid: Vec<[f64; 2]>,
    dof: Vec<f64>,
}

impl Unknowns {
    /// Check u of step `r` and evaluate what is written of it (`mid`: memory to reuse).
    pub fn of(
        path: &Path,
        (space, data): (&CrSpace, Option<&BoundaryData>),
        r: &StepResult,
        mut mid: Vec<[f64; 2]>,
    ) -> Result<Unknowns> {
        let n = r.n;
        if r.u.len() != space.n_dofs {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: format!(
                    "step {n} carries no displacement (solved with want_u = false); every written step needs u"
                ),
            });
        }
        check_finite(path, n, "u", &r.u)?;
        crate::fem::lifting::displacement_into(space, data, &r.u, r.t, &mut mid)?;
        let dof = space.contact.iter().map(|c| r.u[c.dof]).collect();
        let r = StepResult {
            u: Vec::new(),
            mu: r.mu.clone(),
            slip: r.slip.clone(),
            state: r.state.clone(),
            normal: r.normal.clone(),
            rigid: r.rigid.clone(),
            ..*r
        };
        Ok(Unknowns { r, mid, dof })
    }

    /// The step's number.
    pub fn n(&self) -> usize {
        self.r.n
    }
}

impl Writer {
    /// Check step `u.r` and append it to the buffered rows (and frames); an error leaves the buffers as
    /// they were.
    pub(super) fn take(&mut self, u: Unknowns) -> Result<()> {
        let Unknowns { r, mid, dof } = u;
        let (path, n) = (self.path.as_path(), r.n);
        let expected = self.completed + self.rows.count;
        if n != expected {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: format!("step {n} handed to the writer, but the next step is {expected}"),
            });
        }
        check_finite(path, n, "t", &[r.t])?;
        check_finite(path, n, "mu", &r.mu)?;
        check_finite(path, n, "slip", &r.slip)?;
        check_finite(path, n, "energy/residual/wall", &[r.energy, r.residual, r.wall])?;
        if let Some(e) = &r.errors {
            check_finite(path, n, "errors", &[e.energy, e.h1, e.l2])?;
        }
        let sigma_t: Vec<f64> = r.mu.iter().zip(&self.space.contact).map(|(m, c)| -m / c.length).collect();
        check_finite(path, n, "sigma_t", &sigma_t)?;
        if self.frames.is_frame(n) {
            self.fields.eval(&mid, &r, self.prev_slip.as_deref(), &mut self.buf);
            let b = &self.buf;
            for (what, v) in [
                ("displacement", &b.displacement),
                ("strain", &b.strain),
                ("stress", &b.stress),
                ("von_mises", &b.von_mises),
                ("slip_increment", &b.slip_increment),
            ] {
                // as in check_finite: one vectorised pass, the position only when there is one
                if v.iter().fold(true, |ok, x| ok & x.is_finite()) {
                    continue;
                }
                if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                    return Err(Error::Io {
                        path: path.to_path_buf(),
                        msg: format!(
                            "step {n}: {what}[{k}] exceeds the single-precision range (3.4e38) of the VTKHDF/XDMF \
                             views; the step was not written (u is linear in the scene's data together, the loads, u₀, g_a and \
                             the parts' u and gap: scale them down)"
                        ),
                    });
                }
            }
            underflows(path, n, &mid)?;
            self.frame_rows.push(r.t, &self.buf);
            self.frame_steps.push(n);
        }
        self.rows.push(&r, &mid, (&sigma_t, &dof), self.fields.contact_lengths());
        self.mid = mid;
        self.prev_slip = Some(r.slip);
        Ok(())
    }
}

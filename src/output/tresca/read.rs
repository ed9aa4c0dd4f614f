//! Reading a stored step of the `tresca` group back ([`super::Tresca::read_step`]): what `--resume`
//! starts from.

use super::Tresca;
use crate::fem::norms::ErrorNorms;
use crate::fem::space::{CrSpace, EdgeDof};
use crate::friction::EdgeState;
use crate::stepping::StepResult;

impl Tresca {
    /// Rebuild the StepResult of stored step n (exact unknowns, μ, slip, state, statistics).
    pub fn read_step(&self, space: &CrSpace, n: usize) -> hdf5::Result<StepResult> {
        let t = self.times.read::<f64>(n)?[0];
        let mid = self.u.read::<f64>(n)?;
        let mut u = vec![0.0; space.n_dofs];
        for (e, d) in space.edge_dof.iter().enumerate() {
            if let EdgeDof::Free([a, b]) = d {
                u[*a] = mid[2 * e];
                u[*b] = mid[2 * e + 1];
            }
        }
        let (mut mu, mut slip, mut state) = (vec![], vec![], vec![]);
        if let Some([sl, _, st, m, d]) = &self.contact {
            slip = sl.read::<f64>(n)?;
            state = st
                .read::<u8>(n)?
                .into_iter()
                .map(|s| if s == 1 { EdgeState::Slip } else { EdgeState::Stick })
                .collect();
            mu = m.read::<f64>(n)?;
            for (c, s) in space.contact.iter().zip(&d.read::<f64>(n)?) {
                u[c.dof] = *s;
            }
        }
        let errors = match &self.errors {
            Some([en, h1, l2]) => {
                Some(ErrorNorms { energy: en.read::<f64>(n)?[0], h1: h1.read::<f64>(n)?[0], l2: l2.read::<f64>(n)?[0] })
            }
            None => None,
        };
        let mut r = StepResult {
            n,
            t,
            u,
            mu,
            slip,
            state,
            iterations: self.iterations.read::<i64>(n)?[0] as usize,
            residual: self.residual.read::<f64>(n)?[0],
            energy: self.energy.read::<f64>(n)?[0],
            errors,
            wall: self.wall.read::<f64>(n)?[0],
            audit: None,
            normal: Default::default(),
            rigid: vec![],
        };
        if let Some(s) = &self.normal {
            crate::output::normal_series::read_into(s, space, n, &mut r)?;
        }
        if let Some(s) = &self.rigid {
            crate::output::rigid_series::read_into(s, n, &mut r)?;
        }
        Ok(r)
    }
}

//! The rows of consecutive steps buffered between two commits (`super::Writer`), in the shapes of the
//! `tresca` series they are appended to (`super::tresca::Tresca::write_rows`).

use crate::stepping::StepResult;

/// Rows of consecutive steps buffered for one write.
#[derive(Default)]
pub struct Rows {
    pub first: usize,
    pub count: usize,
    pub(super) times: Vec<f64>,
    pub(super) u: Vec<f64>,
    pub(super) energy: Vec<f64>,
    pub(super) iterations: Vec<i64>,
    pub(super) residual: Vec<f64>,
    pub(super) n_stick: Vec<i64>,
    pub(super) n_slip: Vec<i64>,
    pub(super) wall: Vec<f64>,
    pub(super) slip: Vec<f64>,
    pub(super) sigma_t: Vec<f64>,
    pub(super) state: Vec<u8>,
    pub(super) mu: Vec<f64>,
    pub(super) dof: Vec<f64>,
    pub(super) errors: [Vec<f64>; 3],
}

impl Rows {
    pub fn push(&mut self, r: &StepResult, mid: &[[f64; 2]], sigma_t: &[f64], dof: &[f64]) {
        self.count += 1;
        self.times.push(r.t);
        self.u.extend_from_slice(mid.as_flattened());
        self.energy.push(r.energy);
        self.iterations.push(r.iterations as i64);
        self.residual.push(r.residual);
        self.n_stick.push(r.n_stick() as i64);
        self.n_slip.push(r.n_slip() as i64);
        self.wall.push(r.wall);
        self.slip.extend_from_slice(&r.slip);
        self.sigma_t.extend_from_slice(sigma_t);
        self.state.extend(r.state.iter().map(|&s| s as u8));
        self.mu.extend_from_slice(&r.mu);
        self.dof.extend_from_slice(dof);
        if let Some(e) = &r.errors {
            self.errors[0].push(e.energy);
            self.errors[1].push(e.h1);
            self.errors[2].push(e.l2);
        }
    }

    /// Empty the buffer, keeping its memory for the next rows; the next row is step `first`.
    pub fn reset(&mut self, first: usize) {
        self.first = first;
        self.count = 0;
        let f64s = [&mut self.times, &mut self.u, &mut self.energy, &mut self.residual, &mut self.wall, &mut self.slip];
        for v in f64s.into_iter().chain([&mut self.sigma_t, &mut self.mu, &mut self.dof]) {
            v.clear();
        }
        for v in [&mut self.iterations, &mut self.n_stick, &mut self.n_slip] {
            v.clear();
        }
        self.state.clear();
        self.errors.iter_mut().for_each(Vec::clear);
    }
}

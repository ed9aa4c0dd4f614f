//! The rows of consecutive steps buffered between two commits (`super::Writer`), in the shapes of the
//! `tresca` series they are appended to (`super::tresca::Tresca::write_rows`).

use crate::stepping::StepResult;

/// Bytes of buffered rows and frames at which the writer commits even when more steps are queued
/// (`super::Writer::write_unknowns`). On the VMs this project runs on, memory the process has not touched
/// before costs about 2 µs a 4 KiB page (the kernel zeroes it, the hypervisor backs it): a group commit of
/// 16 frames of mms_stop refine 4 (0.9 MB a step) mapped 15 MB of buffers, a fifth of the run's page
/// faults. With the budget the buffers stay a few MB and are reused from commit to commit; a commit costs
/// tens of µs (a few `pwrite`s, the `NSteps` attributes, one flush, the XDMF text).
pub(super) const BUDGET: usize = 4 << 20;

/// Append one step's `v` to the buffer `d`. Into an empty buffer, room for as many steps as a commit
/// can gather is reserved first (at most [`super::background::QUEUE`], at most what fits [`BUDGET`] and
/// one more; address space only, pages are mapped when written), so the buffer is not grown step by step
/// (each growth maps and copies it anew). If the reservation fails, the buffer grows as usual.
pub(super) fn append<T: Copy>(d: &mut Vec<T>, v: &[T]) {
    if d.is_empty() {
        let bytes = std::mem::size_of_val(v).max(1);
        let _ = d.try_reserve(v.len() * BUDGET.div_ceil(bytes).clamp(1, super::background::QUEUE));
    }
    d.extend_from_slice(v);
}

/// Bytes held by the vectors of `vs`.
pub(super) fn bytes<'a, T: 'a>(vs: impl IntoIterator<Item = &'a Vec<T>>) -> usize {
    vs.into_iter().map(|v| std::mem::size_of_val(v.as_slice())).sum()
}

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
    /// The energy audit (`stepping::audit`), in `Audit::as_array`'s order; NaN for a step without one.
    pub(super) audit: [Vec<f64>; 6],
    /// The normal condition (`super::tresca::NORMAL`; empty without normal unknowns).
    pub(super) pressure: Vec<f64>,
    pub(super) gap: Vec<f64>,
    pub(super) status: Vec<u8>,
    /// The exact normal forces P_e and normal unknowns (for `--resume`).
    pub(super) force: Vec<f64>,
    pub(super) normal_dof: Vec<f64>,
    /// α of a floating body (`super::rigid_series`), `rigid_width` values a step (none without).
    pub(super) rigid: Vec<f64>,
    pub(super) rigid_width: usize,
}

impl Rows {
    /// Append step `r` (`lengths`: |e| of the Γ_C edges, for the pressure P_e/|e|; `dof`: the contact
    /// unknown of each Γ_C edge, followed by its normal unknown when the edges have one).
    pub fn push(&mut self, r: &StepResult, mid: &[[f64; 2]], (sigma_t, dof): (&[f64], &[f64]), lengths: &[f64]) {
        self.count += 1;
        self.times.push(r.t);
        append(&mut self.u, mid.as_flattened());
        self.energy.push(r.energy);
        self.iterations.push(r.iterations as i64);
        self.residual.push(r.residual);
        self.n_stick.push(r.n_stick() as i64);
        self.n_slip.push(r.n_slip() as i64);
        self.wall.push(r.wall);
        append(&mut self.slip, &r.slip);
        append(&mut self.sigma_t, sigma_t);
        self.state.extend(r.state.iter().map(|&s| s as u8));
        append(&mut self.mu, &r.mu);
        let (dof, normal_dof) = dof.split_at(lengths.len().min(dof.len()));
        append(&mut self.dof, dof);
        if !r.normal.force.is_empty() {
            append(&mut self.pressure, &r.normal.force.iter().zip(lengths).map(|(p, l)| p / l).collect::<Vec<_>>());
            append(&mut self.gap, &r.normal.gap);
            self.status.extend(super::normal_series::status(r));
            append(&mut self.force, &r.normal.force);
            append(&mut self.normal_dof, normal_dof);
        }
        super::rigid_series::push(&mut self.rigid, r, self.rigid_width);
        let audit = r.audit.map_or([f64::NAN; 6], |a| a.as_array());
        self.audit.iter_mut().zip(audit).for_each(|(v, a)| v.push(a));
        if let Some(e) = &r.errors {
            self.errors[0].push(e.energy);
            self.errors[1].push(e.h1);
            self.errors[2].push(e.l2);
        }
    }

    /// Bytes buffered in the per-unknown and per-contact-edge rows.
    pub fn bytes(&self) -> usize {
        bytes([&self.u, &self.slip, &self.sigma_t, &self.mu, &self.dof, &self.pressure, &self.gap, &self.force])
            + bytes([&self.normal_dof, &self.rigid])
            + self.state.len()
            + self.status.len()
    }

    /// Empty the buffer, keeping its memory for the next rows; the next row is step `first`.
    pub fn reset(&mut self, first: usize) {
        self.first = first;
        self.count = 0;
        let f64s = [&mut self.times, &mut self.u, &mut self.energy, &mut self.residual, &mut self.wall, &mut self.slip];
        let more = [&mut self.sigma_t, &mut self.mu, &mut self.dof, &mut self.pressure, &mut self.gap, &mut self.force];
        for v in f64s.into_iter().chain(more) {
            v.clear();
        }
        for v in [&mut self.iterations, &mut self.n_stick, &mut self.n_slip] {
            v.clear();
        }
        self.state.clear();
        self.status.clear();
        self.normal_dof.clear();
        self.rigid.clear();
        self.errors.iter_mut().for_each(Vec::clear);
        self.audit.iter_mut().for_each(Vec::clear);
    }
}

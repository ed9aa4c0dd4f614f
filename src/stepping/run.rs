//! Running the steps: blocks of steps sharing their triangular solves, their true errors evaluated a
//! few time nodes at a time, and every result handed out in order once K's condition estimate is
//! accepted.

use super::{checked, contact, contact_result, Problem, StepResult};
use crate::error::{Error, Result};
use crate::friction::Friction;
use std::time::Instant;

/// Steps whose true errors are evaluated together (`Problem::finish_block`): the exact solution's
/// spatial values bound to a chunk of elements are then read from memory once for this many time nodes.
/// Few enough that the writer thread gets the first steps of a block early (with all the steps of a
/// block at once the writing no longer overlapped the errors).
const ERROR_BATCH: usize = 4;

/// Bytes of step results held back while K's condition estimate is under way (see [`Held`]); beyond
/// them the steps wait for the estimate. Steps without u (runs with neither a results file nor true
/// errors) take a few hundred bytes each, so those runs never wait; a step with u takes 8 bytes per
/// unknown (200 kB at 24,640 unknowns).
const HOLD_BYTES: usize = 4 << 20;

/// The results not handed out yet because K's condition estimate (`conditioning`) is still under way:
/// step 0, then the steps in order. The steps go on meanwhile; the first step handed out after the
/// verdict hands these out first. (Waiting for the verdict at the first step instead held the steps
/// back: the estimate's solves end well after the factor.)
struct Held {
    first: Option<StepResult>,
    steps: Vec<StepResult>,
    bytes: usize,
}

impl Held {
    /// Keep a copy of `r` if it fits within [`HOLD_BYTES`]; false (nothing kept) otherwise.
    fn hold(&mut self, r: &StepResult) -> bool {
        let b = 8 * (r.u.len() + r.mu.len() + r.slip.len()) + r.state.len() + std::mem::size_of::<StepResult>();
        if self.bytes + b > HOLD_BYTES {
            return false;
        }
        self.bytes += b;
        self.steps.push(r.clone());
        true
    }

    /// Hand out what is held, in order, then `r` (if any).
    fn hand_out(&mut self, r: Option<&StepResult>, on_step: &mut impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        if let Some(f) = self.first.take() {
            on_step(&f)?;
        }
        self.bytes = 0;
        for h in std::mem::take(&mut self.steps) {
            on_step(&h)?;
        }
        r.map_or(Ok(()), on_step)
    }
}

impl Problem {
    /// [`Problem::finish`] for the steps of a block: their true errors evaluated [`ERROR_BATCH`] steps
    /// at a time (`ErrorEvaluator::errors_at`, the same values). Each step is checked and handed to `hand`
    /// in turn; the first failure is returned after the steps before it were handed out.
    fn finish_block(&self, done: Vec<StepResult>, hand: &mut impl FnMut(StepResult) -> Result<()>) -> Result<()> {
        let mut done = done.into_iter().peekable();
        while done.peek().is_some() {
            self.finish_batch(done.by_ref().take(ERROR_BATCH).collect(), hand)?;
        }
        Ok(())
    }

    fn finish_batch(&self, done: Vec<StepResult>, hand: &mut impl FnMut(StepResult) -> Result<()>) -> Result<()> {
        let (mut norms, mut failed) = (Vec::new(), None);
        if let (Some(ev), Some(ex)) = (&self.errors, &self.scene.exact) {
            let with_u: Vec<&StepResult> = done.iter().filter(|r| self.has_u(r)).collect();
            let mids: Vec<Vec<[f64; 2]>> =
                with_u.iter().map(|r| self.displacement(&r.u, r.t)).collect::<Result<_>>()?;
            let fields: Vec<(&[[f64; 2]], f64)> = mids.iter().zip(&with_u).map(|(m, r)| (&m[..], r.t)).collect();
            (norms, failed) = ev.errors_at(&self.mesh, ex, &fields);
        }
        let mut norms = norms.into_iter();
        for r in done {
            let mut r = checked(r, &self.scene)?;
            if self.errors.is_some() && self.scene.exact.is_some() && self.has_u(&r) {
                match norms.next() {
                    Some(e) => r.errors = Some(e),
                    None => {
                        return Err(failed
                            .take()
                            .unwrap_or_else(|| Error::Linear("internal: missing error norms".into())))
                    }
                }
            }
            hand(r)?;
        }
        Ok(())
    }

    /// Steps prev.n + 1, …, N in blocks of steps sharing their triangular
    /// solves (`solve::free::Block`); every completed step goes to `on_step`, in order, before a later
    /// step's error is returned. Returns the last step's result.
    fn run_blocks(
        &self,
        friction: &Friction,
        mut prev: StepResult,
        want: impl Fn(usize) -> bool,
        on_step: &mut impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<StepResult> {
        let mut block = self.free.new_block();
        let mut first = prev.n + 1;
        while first <= self.n_steps() {
            let start = Instant::now();
            let (last, mut failed) = self.free.forward_block(first..=self.n_steps(), &self.scene.times, &mut block)?;
            let mut done = Vec::with_capacity(last + 1 - first);
            let mut solves = start.elapsed().as_secs_f64();
            for n in first..=last {
                let start = Instant::now();
                let t = self.scene.times[n];
                let trace = self.free.block_trace(&block, n);
                let net = self.free.block_net(&block, n);
                match contact(friction, (&trace, &net), done.last().unwrap_or(&prev), n, t) {
                    Ok((sol, slip)) => {
                        let wall = start.elapsed().as_secs_f64();
                        done.push(contact_result(n, t, sol, slip, vec![], f64::NAN, wall));
                    }
                    Err(e) => {
                        // an earlier step than a failed load's
                        failed = Some(e);
                        break;
                    }
                }
            }
            let start = Instant::now();
            let forces: Vec<Vec<f64>> = done.iter().filter(|r| want(r.n)).map(StepResult::forces).collect();
            let wanted: Vec<(usize, &[f64])> =
                done.iter().filter(|r| want(r.n)).zip(&forces).map(|(r, f)| (r.n, &f[..])).collect();
            let mut us = self.free.finish_block(&mut block, &wanted)?.into_iter();
            solves += start.elapsed().as_secs_f64();
            let share = solves / done.len().max(1) as f64;
            for r in done.iter_mut() {
                if want(r.n) {
                    r.u = us.next().unwrap_or_default();
                    self.free.complete(&mut r.u, &r.rigid);
                    r.energy = self.energy_of(block.load(r.n), r);
                }
                r.wall += share;
            }
            self.finish_block(done, &mut |r| {
                on_step(&r)?;
                prev = r;
                Ok(())
            })?;
            if let Some(e) = failed {
                return Err(e);
            }
            first = last + 1;
        }
        Ok(prev)
    }

    /// The one way to run the steps: from step 0 (handed out with the first step: both are computed while
    /// K's condition estimate may still be under way) or after a given step, to N, handing every result to
    /// `on_step` in order and forming u only at the steps `options.want` selects (see [`Problem::step`]).
    pub fn run(
        &self,
        options: RunOptions<impl Fn(usize) -> bool>,
        on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        let RunOptions { after, want, audit } = options;
        // with boundary data the audit also gives a step's energy (2Eⁿ): always run then
        let audit = audit || self.data.is_some();
        match after {
            Some(from) => self.run_handing(from, None, (want, audit), on_step),
            None => {
                let first = self.initial_unchecked().map_err(|e| self.prefer_conditioning(e))?;
                self.run_handing(first.clone(), Some(first), (want, audit), on_step)
            }
        }
    }

    /// Run steps from `from` to N; `first`, if given, is handed out before them. Every result is handed
    /// out only once K's condition estimate is accepted; with `audit`, with its energy audit.
    fn run_handing(
        &self,
        from: StepResult,
        first: Option<StepResult>,
        (want, audit): (impl Fn(usize) -> bool, bool),
        mut on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        // the energy audit of every step handed out, against the state of the step before
        let (first, mut state) = match first {
            Some(f) if audit => {
                let (f, s) = self.audited(None, &f)?;
                (Some(f), s)
            }
            Some(f) => (Some(f), None),
            None if audit => (None, self.audit_state(&from)?),
            None => (None, None),
        };
        let mut held = Held { first, steps: Vec::new(), bytes: 0 };
        let mut hand = |r: &StepResult| -> Result<()> {
            let audited;
            let r = if audit {
                let (a, s) = self.audited(state.as_ref(), r)?;
                state = s;
                audited = a;
                &audited
            } else {
                r
            };
            if !self.conditioning.ready() && held.hold(r) {
                return Ok(());
            }
            self.conditioned()?;
            held.hand_out(Some(r), &mut on_step)
        };
        let result = if from.n >= self.n_steps() {
            // nothing to step: `first` alone (handed out below)
            Ok(())
        } else if let (Some(friction), true) = (&self.friction, self.free.block_size() > 0) {
            self.run_blocks(friction, from, want, &mut hand).map(|_| ())
        } else {
            let mut load = Vec::with_capacity(self.space.n_dofs);
            let mut prev = from;
            (|| {
                for n in prev.n + 1..=self.n_steps() {
                    let r = self.step_unchecked(n, &prev, &mut load, want(n))?;
                    hand(&r)?;
                    prev = r;
                }
                Ok(())
            })()
        };
        // What is still held (step 0 at least, if nothing was handed out) once K is accepted: a run that
        // fails hands out the steps before the failure, as step by step.
        if held.first.is_some() || !held.steps.is_empty() {
            match self.conditioned() {
                Ok(()) => held.hand_out(None, &mut on_step)?,
                Err(c) => return Err(c),
            }
        }
        result.map_err(|e| self.prefer_conditioning(e))
    }
}

/// Where [`Problem::run`] starts and at which steps it forms u.
pub struct RunOptions<W> {
    /// `None`: from step 0 (handed out too); `Some(r)`: the steps after `r` (a resumed run, a study's
    /// levels after their step 0).
    pub after: Option<StepResult>,
    /// The steps at which u is formed (the others carry slip, μ and stick/slip only).
    pub want: W,
    /// Audit the energy of every step ([`super::audit`]); off where no one reads it (a study's levels:
    /// saves a matrix-free a_h product per node). With boundary data the audit always runs: it gives
    /// a step's energy.
    pub audit: bool,
}

impl RunOptions<fn(usize) -> bool> {
    /// Every step from step 0, u formed at each.
    pub fn all() -> Self {
        RunOptions { after: None, want: |_| true, audit: true }
    }

    /// The steps after `r`, u formed at each.
    pub fn after(r: StepResult) -> Self {
        RunOptions { after: Some(r), want: |_| true, audit: true }
    }
}

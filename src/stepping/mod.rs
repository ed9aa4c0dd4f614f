//! Backward Euler in time: set-up once (mesh, space, K assembled and factored once, loads, the
//! condensed friction operator), then for n = 1..N
//!   uⁿ = argmin ½a_h(v,v) − (lⁿ,v) + j_h(v − uⁿ⁻¹),   u⁰ = I_CR u₀,
//! in two calls, as the README describes a step: the free response u_f = K⁻¹lⁿ with its contact trace
//! s_f (`solve::free`), then the friction problem on Γ_C for d = s_f − sⁿ⁻¹ (`friction`), and
//! uⁿ = u_f − K⁻¹Eμ. Without Γ_C a step is the free response alone. Each completed step is handed to a
//! callback (the writer), so nothing is lost if a later step fails.

use crate::error::{Error, Result};
use crate::fem::assemble::{stiffness_values, EdgePattern};
use crate::fem::elasticity::Elasticity;
use crate::fem::loads::Loads;
use crate::fem::norms::{ErrorEvaluator, ErrorNorms};
use crate::fem::space::CrSpace;
use crate::friction::{EdgeState, Friction, FrictionSolution};
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::condense::condense;
use crate::solve::condition;
use crate::solve::factor::{fill_order, Factor, Symbolic};
use crate::solve::free::FreeResponse;
use crate::solve::ordering::{Graph, ND_MIN_SIZE};
use crate::solve::superpose::LoadBasis;
use crate::sparse::{dot, energy};
use conditioning::Pending;
use faer::sparse::SparseColMat;
use std::sync::Arc;
use std::time::Instant;

mod conditioning;
mod setup;
pub use conditioning::MAX_CONDITION;
pub use setup::Problem0;

/// Steps whose true errors are evaluated together (`Problem::finish_block`): the exact solution's
/// spatial values bound to a chunk of elements are then read from memory once for this many time nodes.
/// Few enough that the writer thread gets the first steps of a block early (with all 16 steps of a
/// block at once, mms_stop r4 written took 6 ms longer: the writing no longer overlapped the errors).
const ERROR_BATCH: usize = 4;

/// Everything assembled once per run.
pub struct Problem {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    pub law: Elasticity,
    /// K, the matrix of a_h on V_h.
    pub stiffness: SparseColMat<usize, f64>,
    /// u_f = K⁻¹lⁿ and its contact trace; owns the factor of K.
    pub free: FreeResponse,
    /// The friction problem on Γ_C (`None` without Γ_C: plain elasticity).
    pub friction: Option<Friction>,
    /// True errors (when the scene gives `[exact]`).
    pub errors: Option<ErrorEvaluator>,
    pub setup: SetupTimes,
    /// The condition estimate of K, known by the time a step result is handed out.
    conditioning: conditioning::Pending,
}

/// Wall times of the set-up phases (seconds).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SetupTimes {
    /// Mesh binding and numbering of V_h.
    pub space: f64,
    /// K and the load quadrature (the fill-reducing ordering runs beside them).
    pub assembly: f64,
    /// Cholesky factorisation of K (its condition estimate runs beside what follows).
    pub factorisation: f64,
    /// The load superposition: its probe of the loads at the time nodes and the responses K⁻¹b_j.
    pub superposition: f64,
    /// C = EᵀK⁻¹E and W = L_cc⁻¹ from the factor.
    pub condensation: f64,
}

impl SetupTimes {
    /// In the order written to results files: space, assembly, factorisation, superposition,
    /// condensation.
    pub fn as_array(&self) -> [f64; 5] {
        [self.space, self.assembly, self.factorisation, self.superposition, self.condensation]
    }
}

/// What one time step produced.
#[derive(Clone, Debug)]
pub struct StepResult {
    pub n: usize,
    pub t: f64,
    /// Unknowns of V_h.
    pub u: Vec<f64>,
    /// Friction force per contact edge.
    pub mu: Vec<f64>,
    /// Tangential displacement s_e per contact edge.
    pub slip: Vec<f64>,
    pub state: Vec<EdgeState>,
    pub iterations: usize,
    pub residual: f64,
    /// a_h(uⁿ, uⁿ).
    pub energy: f64,
    pub errors: Option<ErrorNorms>,
    pub wall: f64,
}

impl StepResult {
    pub fn n_slip(&self) -> usize {
        self.state.iter().filter(|&&s| s == EdgeState::Slip).count()
    }
    pub fn n_stick(&self) -> usize {
        self.state.len() - self.n_slip()
    }
}

impl Problem {
    /// Mesh, space, assembly, factorisation and condensation: all the work done once per run.
    pub fn new(scene: Scene) -> Result<Problem> {
        let mesh = Mesh::from_spec(&scene.mesh)?;
        Problem::with_mesh(scene, mesh)
    }

    /// As [`Problem::new`] on a given mesh (the scene's `[mesh]` table is ignored).
    pub fn with_mesh(scene: Scene, mesh: Mesh) -> Result<Problem> {
        Problem::with_mesh_beside(scene, mesh, None::<fn(&Problem0)>).map(|(p, _)| p).map_err(|(e, _)| e)
    }

    /// Number of time steps N.
    pub fn n_steps(&self) -> usize {
        self.scene.times.len() - 1
    }

    /// The step-0 state u⁰ = I_CR u₀.
    pub fn initial(&self) -> Result<StepResult> {
        let r = self.initial_unchecked().map_err(|e| self.prefer_conditioning(e))?;
        self.conditioned()?;
        Ok(r)
    }

    /// K's condition estimate accepted (it waits for the estimate the first time): every step result
    /// passes this before it is handed out (see `conditioning`).
    pub fn conditioned(&self) -> Result<()> {
        self.conditioning.verdict(&self.scene, &self.mesh, &self.space)
    }

    /// A failure of the run, or the refusal of K if that is what it followed from.
    fn prefer_conditioning(&self, e: Error) -> Error {
        match self.conditioned() {
            Err(c) => c,
            Ok(()) => e,
        }
    }

    /// [`Problem::initial`] before the condition estimate is known.
    fn initial_unchecked(&self) -> Result<StepResult> {
        let t = self.scene.times[0];
        let u = match &self.scene.u0 {
            Some(u0) => self.space.interpolate(&self.mesh, u0, t)?,
            None => vec![0.0; self.space.n_dofs],
        };
        let nc = self.space.contact.len();
        let slip = self.space.contact.iter().map(|c| u[c.dof]).collect();
        let energy = energy(&self.stiffness, &u);
        let r = StepResult {
            n: 0,
            t,
            u,
            mu: vec![0.0; nc],
            slip,
            state: vec![EdgeState::Stick; nc],
            iterations: 0,
            residual: 0.0,
            energy,
            errors: None,
            wall: 0.0,
        };
        self.finish(r)
    }

    /// Finiteness check and true errors.
    fn finish(&self, r: StepResult) -> Result<StepResult> {
        let mut r = self.checked(r)?;
        if let (Some(ev), Some(ex), false) = (&self.errors, &self.scene.exact, r.u.is_empty() && self.space.n_dofs > 0)
        {
            r.errors = Some(ev.errors(&self.mesh, ex, &self.space.midpoint_values(&r.u), r.t)?);
        }
        Ok(r)
    }

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
            let with_u: Vec<&StepResult> = done.iter().filter(|r| !r.u.is_empty() || self.space.n_dofs == 0).collect();
            let mids: Vec<Vec<[f64; 2]>> = with_u.iter().map(|r| self.space.midpoint_values(&r.u)).collect();
            let fields: Vec<(&[[f64; 2]], f64)> = mids.iter().zip(&with_u).map(|(m, r)| (&m[..], r.t)).collect();
            (norms, failed) = ev.errors_at(&self.mesh, ex, &fields);
        }
        let mut norms = norms.into_iter();
        for r in done {
            let mut r = self.checked(r)?;
            if self.errors.is_some() && self.scene.exact.is_some() && (!r.u.is_empty() || self.space.n_dofs == 0) {
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

    /// The finiteness checks of a step result.
    fn checked(&self, r: StepResult) -> Result<StepResult> {
        if r.u.iter().any(|v| !v.is_finite()) {
            return Err(Error::Linear(format!(
                "step {}: the solution is not finite (singular or ill-conditioned system)",
                r.n
            )));
        }
        if !r.u.is_empty() && !r.energy.is_finite() {
            let umax = r.u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            return Err(Error::Linear(format!(
                "step {}: the energy a_h(u, u) overflows f64 (max |u| = {umax:.3e}): the loads are too large for \
                 the answer to be representable; u is linear in the loads, u₀ and g_a together, so scale them down",
                r.n
            )));
        }
        Ok(r)
    }

    /// Solve step n from the previous step's result. `load` is scratch space. With `want_u = false` only
    /// the contact state (slip, μ, stick/slip) is computed — enough to continue stepping — and `u` is left
    /// empty, `energy` NaN and no errors: with superposed loads such a step costs O(n_c²), independent of
    /// the mesh.
    pub fn step(&self, n: usize, prev: &StepResult, load: &mut Vec<f64>, want_u: bool) -> Result<StepResult> {
        let r = self.step_unchecked(n, prev, load, want_u).map_err(|e| self.prefer_conditioning(e))?;
        self.conditioned()?;
        Ok(r)
    }

    /// [`Problem::step`] before the condition estimate is known.
    fn step_unchecked(&self, n: usize, prev: &StepResult, load: &mut Vec<f64>, want_u: bool) -> Result<StepResult> {
        let start = Instant::now();
        let t = self.scene.times[n];
        let free = self.free.at(n, t, want_u, load)?;
        let Some(friction) = &self.friction else {
            // a_h(u, u) = (l, u)
            let u = free.u;
            let energy = dot(load, &u);
            let r = StepResult {
                n,
                t,
                u,
                mu: vec![],
                slip: vec![],
                state: vec![],
                iterations: 1,
                residual: 0.0,
                energy,
                errors: None,
                wall: start.elapsed().as_secs_f64(),
            };
            return self.finish(r);
        };
        let (sol, slip) = contact(friction, &free.trace, prev, n, t)?;
        let (mut u, mut energy) = (Vec::new(), f64::NAN);
        if want_u {
            u = self.free.with_friction(free, &sol.mu)?;
            // a_h(u, u) = (l, u) − Σ_e μ_e s_e, since K u = l − Eμ
            energy = dot(load, &u) - dot(&sol.mu, &slip);
        }
        self.finish(contact_result(n, t, sol, slip, u, energy, start.elapsed().as_secs_f64()))
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
                match contact(friction, &trace, done.last().unwrap_or(&prev), n, t) {
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
            let wanted: Vec<(usize, &[f64])> = done.iter().filter(|r| want(r.n)).map(|r| (r.n, &r.mu[..])).collect();
            let mut us = self.free.finish_block(&mut block, &wanted)?.into_iter();
            solves += start.elapsed().as_secs_f64();
            let share = solves / done.len().max(1) as f64;
            for r in done.iter_mut() {
                if want(r.n) {
                    r.u = us.next().unwrap_or_default();
                    // a_h(u, u) = (l, u) − Σ_e μ_e s_e, since K u = l − Eμ
                    r.energy = dot(block.load(r.n), &r.u) - dot(&r.mu, &r.slip);
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

    /// Run steps from `from` to N, forming u only at the steps `want` selects (see [`Problem::step`]).
    pub fn run_selected(
        &self,
        from: StepResult,
        want: impl Fn(usize) -> bool,
        on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        self.run_handing(from, None, want, on_step)
    }

    /// Step 0 and all steps, handing every result to `on_step` (step 0 included), forming u only at
    /// the steps `want` selects. Step 0 is handed out with the first step: both are computed while K's
    /// condition estimate may still be under way.
    pub fn run_all_selected(
        &self,
        want: impl Fn(usize) -> bool,
        on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        let first = self.initial_unchecked().map_err(|e| self.prefer_conditioning(e))?;
        self.run_handing(first.clone(), Some(first), want, on_step)
    }

    /// Run steps from `from` to N; `first`, if given, is handed out before them. Every result is handed
    /// out only once K's condition estimate is accepted.
    fn run_handing(
        &self,
        from: StepResult,
        first: Option<StepResult>,
        want: impl Fn(usize) -> bool,
        mut on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        let mut first = first;
        let mut hand = |r: &StepResult| -> Result<()> {
            self.conditioned()?;
            if let Some(f) = first.take() {
                on_step(&f)?;
            }
            on_step(r)
        };
        let result = if from.n >= self.n_steps() {
            // nothing to step: `first` alone (handed out as the last result)
            match first.take() {
                Some(f) => {
                    self.conditioned()?;
                    on_step(&f)
                }
                None => Ok(()),
            }
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
        if let (Err(_), Some(f)) = (&result, first.take()) {
            // a run that fails before handing out a step still hands out step 0, as step by step
            if self.conditioned().is_ok() {
                on_step(&f)?;
            }
        }
        result.map_err(|e| self.prefer_conditioning(e))
    }

    /// Run steps from `from` (whose result is given) to N, handing every result to `on_step`.
    pub fn run_from(&self, from: StepResult, on_step: impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        self.run_selected(from, |_| true, on_step)
    }

    /// Run all steps, including step 0, handing every result to `on_step`.
    pub fn run(&self, on_step: impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        self.run_all_selected(|_| true, on_step)
    }
}

/// The friction problem of step n for the free trace s_f: its solution and the slip
/// sⁿ = sⁿ⁻¹ + Δs (with d = s_f − sⁿ⁻¹ and Δs = d − Cμ).
fn contact(
    friction: &Friction,
    trace: &[f64],
    prev: &StepResult,
    n: usize,
    t: f64,
) -> Result<(FrictionSolution, Vec<f64>)> {
    let d: Vec<f64> = trace.iter().zip(&prev.slip).map(|(f, s)| f - s).collect();
    let sol = friction.solve(&d, &prev.mu, n, t)?;
    let slip = prev.slip.iter().zip(&sol.slip_increment).map(|(a, b)| a + b).collect();
    Ok((sol, slip))
}

/// A step's result from its friction solution.
fn contact_result(
    n: usize,
    t: f64,
    sol: FrictionSolution,
    slip: Vec<f64>,
    u: Vec<f64>,
    energy: f64,
    wall: f64,
) -> StepResult {
    StepResult {
        n,
        t,
        u,
        mu: sol.mu,
        slip,
        state: sol.state,
        iterations: sol.iterations,
        residual: sol.residual,
        energy,
        errors: None,
        wall,
    }
}

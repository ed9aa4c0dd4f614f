//! Backward Euler in time: set-up once (mesh, space, K factored once, loads, condensed contact operator),
//! then for n = 1..N solve
//!   uⁿ = argmin ½a_h(v,v) − (lⁿ,v) + j_h(v − uⁿ⁻¹),   u⁰ = I_CR u₀,
//! by u_f = K⁻¹lⁿ, the condensed friction QP on Γ_C (`contact`, solved by `ssn`, `uzawa` or `pdas`),
//! and uⁿ = u_f − K⁻¹Eμ. Without Γ_C a step is one pair of triangular solves. Each completed step is
//! handed to a callback (the writer), so nothing is lost if a later step fails.

use crate::assemble::{matvec, stiffness, Loads};
use crate::contact::{classify, Condensed, FrictionSolution, Qp};
use crate::cr::CrSpace;
use crate::error::{Error, Result};
use crate::factor::Factor;
use crate::mesh::Mesh;
use crate::norms::{ErrorEvaluator, ErrorNorms};
use crate::scene::{Method, Scene};
use crate::superpose::LoadBasis;
use crate::{pdas, ssn, uzawa};
use faer::sparse::SparseColMat;
use std::time::Instant;

/// Largest accepted condition-number estimate of K: beyond it fewer than 4 of the 16 digits survive.
pub const MAX_CONDITION: f64 = 1e12;

/// Everything assembled once per run.
pub struct Problem {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    pub k: SparseColMat<usize, f64>,
    pub llt: Factor,
    pub loads: Loads,
    /// Superposition of load patterns, when the loads span few of them (see `superpose`).
    pub basis: Option<LoadBasis>,
    pub condensed: Option<Condensed>,
    pub errors: Option<ErrorEvaluator>,
    /// Wall times of the set-up phases (seconds): mesh+space, assembly, factorisation, condensation.
    pub setup_times: [f64; 4],
    /// Estimated condition number of K.
    pub condition: f64,
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
    /// 0 stick, 1 slip.
    pub state: Vec<u8>,
    pub iterations: usize,
    pub residual: f64,
    /// a_h(uⁿ, uⁿ).
    pub energy: f64,
    pub errors: Option<ErrorNorms>,
    pub wall: f64,
}

impl StepResult {
    pub fn n_slip(&self) -> usize {
        self.state.iter().filter(|&&s| s == 1).count()
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
        let t0 = Instant::now();
        let space = CrSpace::new(&mesh, &scene.parts)?;
        let t1 = Instant::now();
        let k = stiffness(&mesh, &space, &scene.material, scene.rho)?;
        let loads = Loads::new(&scene, &mesh, &space);
        let t2 = Instant::now();
        let llt = Factor::new(&k, std::env::var_os("TRESCA_SIMPLICIAL").is_some())?;
        // A nearly singular K (ρ → 0: plain CR fails Korn's inequality; ν → ½ far beyond locking-free
        // ranges) factorises without complaint but returns meaningless displacements: refuse it.
        let kappa = llt.condition_estimate(&k, 12);
        if !(kappa < MAX_CONDITION) {
            return Err(Error::Linear(format!(
                "the stiffness matrix is too ill-conditioned (condition number ≳ {kappa:.1e} > {MAX_CONDITION:.0e}; \
                 rho = {}, E = {}, nu = {}): results would keep fewer than 4 correct digits. \
                 Use rho of order 1 or more (without the jump term CR fails Korn's inequality)",
                scene.rho, scene.material.e, scene.material.nu
            )));
        }
        let t3 = Instant::now();
        let condensed = if space.contact.is_empty() { None } else { Some(Condensed::new(&space, &llt)) };
        let basis = LoadBasis::build(&loads, &space, &scene.times, &llt)?;
        let t4 = Instant::now();
        let errors = scene.exact.as_ref().map(|_| ErrorEvaluator::new(&mesh, &space, &scene.material, scene.rho));
        let d = |a: Instant, b: Instant| (b - a).as_secs_f64();
        Ok(Problem {
            setup_times: [d(t0, t1), d(t1, t2), d(t2, t3), d(t3, t4)],
            condition: kappa,
            scene,
            mesh,
            space,
            k,
            llt,
            loads,
            basis,
            condensed,
            errors,
        })
    }

    /// Number of time steps N.
    pub fn n_steps(&self) -> usize {
        self.scene.times.len() - 1
    }

    /// The step-0 state u⁰ = I_CR u₀.
    pub fn initial(&self) -> Result<StepResult> {
        let t = self.scene.times[0];
        let u = match &self.scene.u0 {
            Some(u0) => self.space.interpolate(&self.mesh, u0, t)?,
            None => vec![0.0; self.space.n_dofs],
        };
        let nc = self.space.contact.len();
        let slip = self.space.contact.iter().map(|c| u[c.dof]).collect();
        let mut ku = vec![0.0; u.len()];
        matvec(&self.k, &u, &mut ku);
        let energy = u.iter().zip(&ku).map(|(a, b)| a * b).sum();
        let r = StepResult {
            n: 0,
            t,
            u,
            mu: vec![0.0; nc],
            slip,
            state: vec![0; nc],
            iterations: 0,
            residual: 0.0,
            energy,
            errors: None,
            wall: 0.0,
        };
        self.finish(r)
    }

    /// Finiteness check and true errors.
    fn finish(&self, mut r: StepResult) -> Result<StepResult> {
        if r.u.iter().any(|v| !v.is_finite()) {
            return Err(Error::Linear(format!(
                "step {}: the solution is not finite (singular or ill-conditioned system)",
                r.n
            )));
        }
        if let (Some(ev), Some(ex), false) = (&self.errors, &self.scene.exact, r.u.is_empty() && self.space.n_dofs > 0)
        {
            r.errors = Some(ev.errors(&self.mesh, ex, &self.space.midpoint_values(&r.u), r.t)?);
        }
        Ok(r)
    }

    /// Solve step n from the previous step's result. `load` is scratch space. With `want_u = false` only
    /// the contact state (slip, μ, stick/slip) is computed — enough to continue stepping — and `u` is left
    /// empty, `energy` NaN and no errors: with superposed loads such a step costs O(n_c²), independent of
    /// the mesh.
    pub fn step(&self, n: usize, prev: &StepResult, load: &mut Vec<f64>, want_u: bool) -> Result<StepResult> {
        let start = Instant::now();
        let t = self.scene.times[n];
        let dofs = self.space.n_dofs;
        let mut u = Vec::new();
        // u_f = K⁻¹ l(t) where needed; its contact trace s_f always
        let s_free: Vec<f64> = match (&self.basis, &self.condensed) {
            (Some(b), cd) => {
                if want_u || cd.is_none() {
                    b.load(n, dofs, load);
                    b.response(n, dofs, &mut u);
                }
                cd.as_ref().map(|c| b.response_at(n, &c.dofs)).unwrap_or_default()
            }
            (None, cd) => {
                self.loads.assemble(&self.space, t, load)?;
                match cd {
                    Some(c) if !want_u && c.z.is_some() => c.trace_of_solution(load),
                    _ => {
                        u.extend_from_slice(load);
                        self.llt.solve_in_place(&mut u);
                        cd.as_ref().map(|c| c.dofs.iter().map(|&k| u[k]).collect()).unwrap_or_default()
                    }
                }
            }
        };
        let Some(cd) = &self.condensed else {
            // a_h(u, u) = (l, u)
            let energy = load.iter().zip(&u).map(|(a, b)| a * b).sum();
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
        let d: Vec<f64> = s_free.iter().zip(&prev.slip).map(|(f, s)| f - s).collect();
        let qp = Qp { c: &cd.c, d: &d, w: &cd.w };
        let s = &self.scene.solver;
        let sol: Result<FrictionSolution> = match s.method {
            Method::Ssn => ssn::solve(&qp, &prev.mu, s.tol, s.max_iter()),
            Method::Pdas => pdas::solve(&qp, &prev.mu, s.tol, s.max_iter()),
            Method::Uzawa => {
                let rho = if s.uzawa_step > 0.0 { s.uzawa_step } else { uzawa::auto_step(&qp, &cd.g) };
                uzawa::solve(&qp, &cd.g, &prev.mu, rho, s.tol, s.max_iter())
            }
        };
        let sol = sol.map_err(|e| match e {
            Error::NotConverged { solver, iterations, residual, tol, .. } => {
                Error::NotConverged { step: n, time: t, solver, iterations, residual, tol }
            }
            other => other,
        })?;
        // s = s_f − Cμ
        let ds = qp.slip_increment(&sol.mu);
        let slip: Vec<f64> = prev.slip.iter().zip(&ds).map(|(a, b)| a + b).collect();
        let state = classify(&qp, &sol.mu, &ds);
        let mut energy = f64::NAN;
        if want_u {
            cd.apply_friction(&self.llt, &mut u, &sol.mu);
            // a_h(u, u) = (l, u) − Σ_e μ_e s_e, since K u = l − Eμ
            let load_work: f64 = load.iter().zip(&u).map(|(a, b)| a * b).sum();
            energy = load_work - sol.mu.iter().zip(&slip).map(|(m, s)| m * s).sum::<f64>();
        }
        let r = StepResult {
            n,
            t,
            u,
            mu: sol.mu,
            slip,
            state,
            iterations: sol.iterations,
            residual: sol.residual,
            energy,
            errors: None,
            wall: start.elapsed().as_secs_f64(),
        };
        self.finish(r)
    }

    /// Run steps from `from` to N, forming u only at the steps `want` selects (see [`Problem::step`]).
    pub fn run_selected(
        &self,
        from: StepResult,
        want: impl Fn(usize) -> bool,
        mut on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        let mut load = Vec::with_capacity(self.space.n_dofs);
        let mut prev = from;
        for n in prev.n + 1..=self.n_steps() {
            let r = self.step(n, &prev, &mut load, want(n))?;
            on_step(&r)?;
            prev = r;
        }
        Ok(())
    }

    /// Run steps from `from` (whose result is given) to N, handing every result to `on_step`.
    pub fn run_from(&self, from: StepResult, on_step: impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        self.run_selected(from, |_| true, on_step)
    }

    /// Run all steps, including step 0, handing every result to `on_step`.
    pub fn run(&self, mut on_step: impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        let first = self.initial()?;
        on_step(&first)?;
        self.run_from(first, on_step)
    }
}

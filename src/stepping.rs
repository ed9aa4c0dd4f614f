//! Backward Euler in time: set-up once (mesh, space, K factored once, loads, condensed contact operator),
//! then for n = 1..N solve
//!   uⁿ = argmin ½a_h(v,v) − (lⁿ,v) + j_h(v − uⁿ⁻¹),   u⁰ = I_CR u₀,
//! by u_f = K⁻¹lⁿ, the condensed friction QP on Γ_C (`contact`, solved by `ssn`, `uzawa` or `pdas`),
//! and uⁿ = u_f − K⁻¹Eμ. Without Γ_C a step is one pair of triangular solves. Each completed step is
//! handed to a callback (the writer), so nothing is lost if a later step fails.

use crate::assemble::{matvec, stiffness, Loads};
use crate::contact::{classify, solve_in_place, Condensed, FrictionSolution, Qp};
use crate::cr::CrSpace;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::norms::{ErrorEvaluator, ErrorNorms};
use crate::scene::{Method, Scene};
use crate::{pdas, ssn, uzawa};
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::SparseColMat;
use faer::Side;
use std::time::Instant;

/// Everything assembled once per run.
pub struct Problem {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    pub k: SparseColMat<usize, f64>,
    pub llt: Llt<usize, f64>,
    pub loads: Loads,
    pub condensed: Option<Condensed>,
    pub errors: Option<ErrorEvaluator>,
    /// Wall times of the set-up phases (seconds): mesh+space, assembly, factorisation, condensation.
    pub setup_times: [f64; 4],
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
        let sym = SymbolicLlt::try_new(k.symbolic(), Side::Lower)
            .map_err(|e| Error::Linear(format!("symbolic Cholesky failed: {e:?}")))?;
        let llt = Llt::try_new_with_symbolic(sym, k.as_ref(), Side::Lower).map_err(|e| {
            Error::Linear(format!("the stiffness matrix is not positive definite ({e:?}): are rigid motions fixed by a Dirichlet part?"))
        })?;
        let t3 = Instant::now();
        let condensed = if space.contact.is_empty() {
            None
        } else {
            Some(Condensed::new(&space, &llt))
        };
        let t4 = Instant::now();
        let errors = scene
            .exact
            .as_ref()
            .map(|_| ErrorEvaluator::new(&mesh, &space, &scene.material, scene.rho));
        let d = |a: Instant, b: Instant| (b - a).as_secs_f64();
        Ok(Problem {
            setup_times: [d(t0, t1), d(t1, t2), d(t2, t3), d(t3, t4)],
            scene,
            mesh,
            space,
            k,
            llt,
            loads,
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
        self.finish(0, t, u, vec![0.0; nc], slip, vec![0; nc], 0, 0.0, 0.0)
    }

    #[allow(clippy::too_many_arguments)]
    fn finish(
        &self,
        n: usize,
        t: f64,
        u: Vec<f64>,
        mu: Vec<f64>,
        slip: Vec<f64>,
        state: Vec<u8>,
        iterations: usize,
        residual: f64,
        wall: f64,
    ) -> Result<StepResult> {
        let mut ku = vec![0.0; u.len()];
        matvec(&self.k, &u, &mut ku);
        let energy = u.iter().zip(&ku).map(|(a, b)| a * b).sum();
        let errors = match (&self.errors, &self.scene.exact) {
            (Some(ev), Some(ex)) => {
                Some(ev.errors(&self.mesh, ex, &self.space.midpoint_values(&u), t)?)
            }
            _ => None,
        };
        if u.iter().any(|v| !v.is_finite()) {
            return Err(Error::Linear(format!(
                "step {n}: the solution is not finite (singular or ill-conditioned system)"
            )));
        }
        Ok(StepResult {
            n,
            t,
            u,
            mu,
            slip,
            state,
            iterations,
            residual,
            energy,
            errors,
            wall,
        })
    }

    /// Solve step n from the previous step's result. `load` is scratch space.
    pub fn step(&self, n: usize, prev: &StepResult, load: &mut Vec<f64>) -> Result<StepResult> {
        let start = Instant::now();
        let t = self.scene.times[n];
        self.loads.assemble(&self.space, t, load)?;
        let mut u = load.clone();
        solve_in_place(&self.llt, &mut u);
        let Some(cd) = &self.condensed else {
            return self.finish(
                n,
                t,
                u,
                vec![],
                vec![],
                vec![],
                1,
                0.0,
                start.elapsed().as_secs_f64(),
            );
        };
        let d: Vec<f64> = cd
            .dofs
            .iter()
            .zip(&prev.slip)
            .map(|(&k, s)| u[k] - s)
            .collect();
        let qp = Qp {
            c: &cd.c,
            d: &d,
            w: &cd.w,
        };
        let s = &self.scene.solver;
        let sol: Result<FrictionSolution> = match s.method {
            Method::Ssn => ssn::solve(&qp, &prev.mu, s.tol, s.max_iter),
            Method::Pdas => pdas::solve(&qp, &prev.mu, s.tol, s.max_iter),
            Method::Uzawa => {
                let rho = if s.uzawa_step > 0.0 {
                    s.uzawa_step
                } else {
                    uzawa::auto_step(&qp, &cd.g)
                };
                uzawa::solve(&qp, &cd.g, &prev.mu, rho, s.tol, s.max_iter)
            }
        };
        let sol = sol.map_err(|e| match e {
            Error::NotConverged {
                solver,
                iterations,
                residual,
                tol,
                ..
            } => Error::NotConverged {
                step: n,
                time: t,
                solver,
                iterations,
                residual,
                tol,
            },
            other => other,
        })?;
        cd.apply_friction(&self.llt, &mut u, &sol.mu);
        let slip: Vec<f64> = cd.dofs.iter().map(|&k| u[k]).collect();
        let ds: Vec<f64> = slip.iter().zip(&prev.slip).map(|(a, b)| a - b).collect();
        let state = classify(&qp, &sol.mu, &ds);
        self.finish(
            n,
            t,
            u,
            sol.mu,
            slip,
            state,
            sol.iterations,
            sol.residual,
            start.elapsed().as_secs_f64(),
        )
    }

    /// Run steps from `from` (whose result is given) to N, handing every result to `on_step`.
    pub fn run_from(
        &self,
        from: StepResult,
        mut on_step: impl FnMut(&StepResult) -> Result<()>,
    ) -> Result<()> {
        let mut load = Vec::with_capacity(self.space.n_dofs);
        let mut prev = from;
        for n in prev.n + 1..=self.n_steps() {
            let r = self.step(n, &prev, &mut load)?;
            on_step(&r)?;
            prev = r;
        }
        Ok(())
    }

    /// Run all steps, including step 0, handing every result to `on_step`.
    pub fn run(&self, mut on_step: impl FnMut(&StepResult) -> Result<()>) -> Result<()> {
        let first = self.initial()?;
        on_step(&first)?;
        self.run_from(first, on_step)
    }
}

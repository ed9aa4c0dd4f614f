//! Backward Euler in time: set-up once (mesh, space, K assembled and factored once, loads, the
//! condensed friction operator), then for n = 1..N
//!   uⁿ = argmin ½a_h(v,v) − (lⁿ,v) + j_h(v − uⁿ⁻¹),   u⁰ = I_CR u₀,
//! in two calls, as docs/model.md describes a step: the free response u_f = K⁻¹lⁿ with its contact trace
//! s_f (`solve::free`), then the friction problem on Γ_C for d = s_f − sⁿ⁻¹ (`friction`), and
//! uⁿ = u_f − K⁻¹Eμ. Without Γ_C a step is the free response alone. Each completed step is handed to a
//! callback (the writer), so nothing is lost if a later step fails, with its energy audit ([`audit`]).
//! With boundary data (`fem::lifting`) u above is w, the unknowns; the displacement is w + u_L(tₙ)
//! ([`Problem::displacement`]), which the errors, the audit and the results file use.

use crate::error::{Error, Result};
use crate::fem::elasticity::Elasticity;
use crate::fem::lifting::{self, BoundaryData};
use crate::fem::norms::{ErrorEvaluator, ErrorNorms};
use crate::fem::space::CrSpace;
use crate::friction::{EdgeState, Friction, FrictionSolution};
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::free::FreeResponse;
use crate::sparse::{dot, symmetric_energy};
use faer::sparse::SparseColMat;
use std::sync::Arc;
use std::time::Instant;

pub mod audit;
mod conditioning;
mod normal;
mod run;
mod setup;
mod shared;
pub mod timeline;

pub use audit::{Audit, AuditState};
pub use conditioning::{Guard, MAX_CONDITION};
use normal::initial_normal;
pub use normal::NormalState;
pub use run::RunOptions;
pub use setup::Discretised;
pub use shared::MeshSetUp;

/// Everything assembled once per run.
pub struct Problem {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    /// Nonzero boundary data u_D, g_n (`None` without: u = w, the unknowns alone).
    pub data: Option<BoundaryData>,
    pub law: Elasticity,
    /// K, the matrix of a_h on V_h, its lower triangle (rows ≥ columns; what the factorisation reads, and
    /// half the memory: `sparse::symmetric_matvec`); shared by the problems on one mesh's set-up
    /// ([`MeshSetUp`]).
    pub stiffness: Arc<SparseColMat<usize, f64>>,
    /// u_f = K⁻¹lⁿ and its contact trace; owns the factor of K.
    pub free: FreeResponse,
    /// The friction problem on Γ_C (`None` without Γ_C: plain elasticity).
    pub friction: Option<Friction>,
    /// True errors (when the scene gives `[exact]`).
    pub errors: Option<Arc<ErrorEvaluator>>,
    pub setup: SetupTimes,
    /// The set-up phases' times of the mesh's shared set-up when this problem reused one
    /// ([`Problem::on_shared`]: K was neither assembled nor factorised again; `setup` holds only its own
    /// load superposition); `None` when it made its own.
    pub reused: Option<SetupTimes>,
    /// The condition estimate of K, known by the time a step result is handed out (shared with the
    /// other problems on the same [`MeshSetUp`]).
    conditioning: Arc<conditioning::Pending>,
    /// Step 0, computed during the set-up beside the numeric factorisation (`None` if that failed: it is
    /// then computed again when asked for, and fails with its error).
    step0: Option<StepResult>,
    /// The energy audit's forms, made at the first audited step.
    forms: std::sync::OnceLock<crate::fem::forms::FullForm>,
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
    /// The step's energy audit (`None` for a step without u, or not run through [`Problem::run`]'s
    /// family).
    pub audit: Option<Audit>,
    /// The normal condition per Γ_C edge (empty without normal unknowns).
    pub normal: NormalState,
    /// α, the rigid motion of a floating body in u = K⁺(l − Eλ) + Rα (`solve::kernel`; empty otherwise).
    pub rigid: Vec<f64>,
}

impl StepResult {
    pub fn n_slip(&self) -> usize {
        self.state.iter().filter(|&&s| s == EdgeState::Slip).count()
    }
    pub fn n_stick(&self) -> usize {
        self.state.len() - self.n_slip()
    }

    /// The contact forces λ = (μ, P) in the order of the condensed problem (μ alone without normal
    /// unknowns).
    pub fn forces(&self) -> Vec<f64> {
        let mut f = self.mu.clone();
        f.extend_from_slice(&self.normal.force);
        f
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
        Problem::with_mesh_guarded(scene, mesh, Guard::Estimate)
    }

    /// [`Problem::with_mesh`], with the condition estimate only if `guard` asks for it (`conditioning`).
    pub fn with_mesh_guarded(scene: Scene, mesh: Mesh, guard: Guard) -> Result<Problem> {
        Problem::with_mesh_beside(scene, mesh, guard, None::<fn(&Discretised)>).map(|(p, _)| p).map_err(|(e, _)| e)
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
        match &self.step0 {
            Some(r) => Ok(r.clone()),
            None => initial_state(self.discretised(), &self.stiffness, self.errors.as_deref()),
        }
    }

    /// The displacement u = w + u_L(t) at every edge midpoint from the unknowns `w` at time t
    /// ([`lifting::displacement`]: the unknowns' midpoint values without boundary data).
    pub fn displacement(&self, w: &[f64], t: f64) -> Result<Vec<[f64; 2]>> {
        lifting::displacement(&self.space, self.data.as_ref(), w, t)
    }

    fn discretised(&self) -> Parts<'_> {
        Parts { scene: &self.scene, mesh: &self.mesh, space: &self.space, data: self.data.as_ref() }
    }

    /// Finiteness check and true errors.
    fn finish(&self, r: StepResult) -> Result<StepResult> {
        finish(r, self.discretised(), self.errors.as_deref())
    }

    /// True if `r` carries u (it is formed only at the steps a run wants; an empty space has none).
    fn has_u(&self, r: &StepResult) -> bool {
        has_u(&self.space, r)
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
                audit: None,
                normal: NormalState::default(),
                rigid: vec![],
            };
            return self.finish(r);
        };
        let (sol, slip) = contact(friction, (&free.trace, &free.net), prev, n, t)?;
        let mut r = contact_result(n, t, sol, slip, Vec::new(), f64::NAN, 0.0);
        if want_u {
            r.u = self.free.with_friction(free, &r.forces())?;
            self.free.complete(&mut r.u, &r.rigid);
            r.energy = self.energy_of(load, &r);
        }
        r.wall = start.elapsed().as_secs_f64();
        self.finish(r)
    }
}

/// The friction problem of step n for the free trace s_f: its solution and the slip
/// sⁿ = sⁿ⁻¹ + Δs (with d = s_f − sⁿ⁻¹ and Δs = d − Cμ; with normal unknowns d also holds
/// r_f − ḡ(tₙ), `friction::normal`). A floating body's net load e = Rᵀlⁿ comes with the trace
/// (`friction::floating`; empty otherwise).
fn contact(
    friction: &Friction,
    (trace, net): (&[f64], &[f64]),
    prev: &StepResult,
    n: usize,
    t: f64,
) -> Result<(FrictionSolution, Vec<f64>)> {
    let mut d: Vec<f64> = trace.iter().zip(&prev.slip).map(|(f, s)| f - s).collect();
    let sol = match friction.normal() {
        None if friction.is_floating() => friction.solve_rigid(&d, (&prev.mu, &prev.rigid), net, n, t)?,
        None => friction.solve(&d, &prev.mu, n, t)?,
        Some(nm) => {
            let nc = prev.slip.len();
            d.truncate(nc);
            d.extend(trace[nc..].iter().zip(nm.gaps(t)?).map(|(r, g)| r - g));
            friction.solve_rigid(&d, (&prev.forces(), &prev.rigid), net, n, t)?
        }
    };
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
        audit: None,
        normal: NormalState { force: sol.normal, gap: sol.gap, separated: sol.separated },
        rigid: sol.rigid,
    }
}

/// Step 0: u⁰ = I_CR u₀ (zero without u₀), its energy, finiteness check and true errors.
fn initial_state(
    d: Parts<'_>,
    stiffness: &SparseColMat<usize, f64>,
    errors: Option<&ErrorEvaluator>,
) -> Result<StepResult> {
    let (scene, mesh, space) = (d.scene, d.mesh, d.space);
    let t = scene.times[0];
    let u = match &scene.u0 {
        Some(u0) => space.interpolate(mesh, u0, t)?,
        None => vec![0.0; space.n_dofs],
    };
    let nc = space.contact.len();
    let slip = space.contact.iter().map(|c| u[c.dof]).collect();
    let energy = symmetric_energy(stiffness, &u);
    let normal = initial_normal(d, &u)?;
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
        audit: None,
        normal,
        rigid: vec![],
    };
    finish(r, d, errors)
}

/// Finiteness check and true errors (when the scene gives `[exact]`).
fn finish(r: StepResult, d: Parts<'_>, errors: Option<&ErrorEvaluator>) -> Result<StepResult> {
    let mut r = checked(r, d.scene)?;
    if let (Some(ev), Some(ex), true) = (errors, &d.scene.exact, has_u(d.space, &r)) {
        let mid = lifting::displacement(d.space, d.data, &r.u, r.t)?;
        r.errors = Some(ev.errors(d.mesh, ex, &mid, r.t)?);
    }
    Ok(r)
}

/// The discretised problem's parts that step 0 and a step's finish read.
#[derive(Clone, Copy)]
struct Parts<'a> {
    scene: &'a Scene,
    mesh: &'a Mesh,
    space: &'a CrSpace,
    data: Option<&'a BoundaryData>,
}

/// True if `r` carries u (it is formed only at the steps a run wants; an empty space has none).
fn has_u(space: &CrSpace, r: &StepResult) -> bool {
    !r.u.is_empty() || space.n_dofs == 0
}

/// The finiteness checks of a step result of `scene`.
fn checked(r: StepResult, scene: &Scene) -> Result<StepResult> {
    if r.u.iter().any(|v| !v.is_finite()) {
        return Err(Error::Linear(format!(
            "step {}: the solution is not finite (singular or ill-conditioned system)",
            r.n
        )));
    }
    if !r.u.is_empty() && !r.energy.is_finite() {
        let umax = r.u.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        return Err(Error::Linear(format!(
            "step {}: the energy a_h(u, u) overflows f64 (max |u| = {umax:.3e}): the data are too large for \
             the answer to be representable; {}",
            r.n,
            scene.scale_data("down")
        )));
    }
    Ok(r)
}

//! The guard against a nearly singular stiffness matrix: a K whose condition-number estimate
//! (`solve::condition`) exceeds [`MAX_CONDITION`] is refused with the likeliest cause named.
//!
//! The estimate (λ_max(K) by products with K, then λ_max(K⁻¹) by a few passes over the factor) runs on a
//! thread of its own ([`Pending`]) from the end of the factorisation, while the set-up ends and the first
//! steps are computed (beside the factorisation it would take a core from the factorisation's threads); no step result is handed out
//! before the verdict (`Problem::conditioned`): the steps computed before it are held back (up to a
//! budget, `stepping::run`), and a run that fails before it reports a refused K rather than what
//! followed from it.
//!
//! A planner's pilots ([`Guard::Skip`]) estimate it on their first mesh only: a run of the plan checks its
//! own K, and the pilots' walls model its cost, not their guard's.

use crate::error::{Error, Result};
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::cholesky::Factor;
use crate::solve::condition;
use faer::sparse::SparseColMat;
use std::sync::{Arc, Mutex, OnceLock};
use std::thread::JoinHandle;

/// Whether a set-up estimates K's condition number.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Guard {
    /// Estimate it and refuse a nearly singular K (every run).
    #[default]
    Estimate,
    /// Accept K unchecked: a planner's pilot on a mesh other than the one its guard ran on (module doc).
    Skip,
}

/// Lanczos steps of each half of the estimate at most (`solve::condition`), one vector of n values each.
pub(super) const LAMBDA_ITERS: usize = 12;

/// The condition estimate λ_max(K) · λ_max(K⁻¹) of a run, under way on its own thread.
pub(super) struct Pending {
    solves: Mutex<Option<JoinHandle<f64>>>,
    /// The estimate computed on the caller's thread, where the system refused it a thread.
    here: Option<f64>,
    /// `None` once K is accepted, else the message it was refused with.
    verdict: OnceLock<Option<String>>,
}

impl Pending {
    /// Start the estimate of K (its lower triangle `k`) with its factor; where no thread can be started,
    /// it is made here.
    pub(super) fn start(factor: &Arc<Factor>, k: &Arc<SparseColMat<usize, f64>>) -> Pending {
        let (f, kk) = (Arc::clone(factor), Arc::clone(k));
        let solves = std::thread::Builder::new().spawn(move || estimate(&f, &kk));
        let here = solves.is_err().then(|| estimate(factor, k));
        Pending { solves: Mutex::new(solves.ok()), here, verdict: OnceLock::new() }
    }

    /// No estimate ([`Guard::Skip`]): K is accepted.
    pub(super) fn skipped() -> Pending {
        Pending { solves: Mutex::new(None), here: None, verdict: OnceLock::from(None) }
    }

    /// Whether the estimate is in (or its thread ended): [`Pending::verdict`] would not wait.
    pub(super) fn ready(&self) -> bool {
        self.verdict.get().is_some()
            || self.solves.lock().unwrap_or_else(|e| e.into_inner()).as_ref().is_none_or(|h| h.is_finished())
    }

    /// Wait for the estimate (once) and refuse K if it is too large.
    pub(super) fn verdict(&self, scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<()> {
        let v = self.verdict.get_or_init(|| {
            let solves = self.solves.lock().unwrap_or_else(|e| e.into_inner()).take();
            match (solves.map(|h| h.join()), self.here) {
                (Some(Ok(kappa)), _) | (None, Some(kappa)) => check(kappa, scene, mesh, space).err(),
                _ => Some("the condition estimate failed".into()),
            }
        });
        match v {
            None => Ok(()),
            Some(msg) => Err(Error::Linear(msg.clone())),
        }
    }
}

/// λ_max(K) · λ_max(K⁻¹) (`solve::condition`).
fn estimate(factor: &Factor, k: &SparseColMat<usize, f64>) -> f64 {
    let top = condition::largest_eigenvalue(k, LAMBDA_ITERS);
    top * condition::largest_inverse_eigenvalue(factor, k.nrows(), LAMBDA_ITERS)
}

/// Largest accepted condition-number estimate of K: beyond it fewer than 4 of the 16 digits survive.
pub const MAX_CONDITION: f64 = 1e12;

/// Refuse the run when `kappa` (the estimate, a lower bound) is not below [`MAX_CONDITION`]: ρ → 0 (plain CR
/// fails Korn's inequality) or ν → ½ far beyond locking-free ranges factorise without complaint but give
/// meaningless displacements.
fn check(kappa: f64, scene: &Scene, mesh: &Mesh, space: &CrSpace) -> std::result::Result<(), String> {
    if kappa < MAX_CONDITION {
        return Ok(());
    }
    Err(format!(
        "the stiffness matrix is too ill-conditioned (condition number ≳ {kappa:.1e} > {MAX_CONDITION:.0e}; \
         rho = {}, E = {}, nu = {}): results would keep fewer than 4 correct digits. Likely cause: {}",
        scene.rho,
        scene.material.e,
        scene.material.nu,
        ill_conditioning_cause(scene, mesh, space)
    ))
}

/// The likeliest reason for an ill-conditioned K, for its message: a piece of the body held by no
/// Dirichlet edge, slivers, a weak jump term, near-incompressibility.
fn ill_conditioning_cause(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> String {
    let dirichlet = |e: usize| space.edge_part[e].is_some_and(|p| scene.parts[p].kind.is_dirichlet());
    if let Some(p) = mesh.floating_piece(dirichlet) {
        return format!(
            "a piece of the mesh (through ({:e}, {:e})) shares no edge with the rest and has no Dirichlet edge: it \
             floats; connect it or clamp part of it",
            p[0], p[1]
        );
    }
    let (aspect, at) = mesh.worst_aspect();
    if aspect > 1e3 {
        return format!(
            "triangles of aspect ratio up to {aspect:.1e} (near ({:e}, {:e})); use better-shaped triangles",
            at[0], at[1]
        );
    }
    if scene.rho < 1.0 {
        return "rho < 1: use rho of order 1 or more (without the jump term CR fails Korn's inequality)".into();
    }
    if scene.material.nu > 0.49 {
        return "nu close to 1/2 (near-incompressible): lambda/mu is huge".into();
    }
    "none of a floating piece, slivers (aspect ratio > 1e3), rho < 1 or nu near 1/2: check the scale of E and \
     of the coordinates"
        .into()
}

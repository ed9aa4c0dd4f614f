//! The set-up of a mesh shared by the problems on it that differ only in their time grid
//! ([`MeshSetUp`], [`Problem::on_shared`]): the levels of a study or a plan with the same refinement.

use super::conditioning::{Guard, Pending};
use super::setup::Discretised;
use super::{Problem, SetupTimes, StepResult};
use crate::error::{Error, Result};
use crate::fem::elasticity::Elasticity;
use crate::fem::lifting::BoundaryData;
use crate::fem::loads::Loads;
use crate::fem::norms::ErrorEvaluator;
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::cholesky::Factor;
use crate::solve::condense::Condensation;
use crate::solve::free::FreeResponse;
use crate::solve::kernel::Kernel;
use crate::solve::superpose::LoadBasis;
use faer::sparse::SparseColMat;
use std::sync::Arc;
use std::time::Instant;

impl Problem {
    /// The problem of `scene` on the set-up `shared` of its mesh (made by [`MeshSetUp::new`] from a scene
    /// that differs from this one at most in its time grid): only the load superposition, which depends
    /// on the time nodes, is computed; K, its factor, the condensation and the condition estimate are
    /// shared (the same values, so the same results as [`Problem::new`], bit for bit).
    pub fn on_shared(scene: Scene, shared: &MeshSetUp) -> Result<Problem> {
        let m = shared;
        if scene.times.first() != m.t0.as_ref() {
            return Err(Error::Linear("internal: a shared set-up used with another initial time".into()));
        }
        // the shared set-up checked the data at its own scene's time nodes: this one's are checked here
        crate::fem::lifting::consistency::check(&scene, &m.mesh, &m.space)?;
        let t3 = Instant::now();
        let mut assembled = Vec::new();
        let basis = LoadBasis::build(&m.loads, &scene.times, &m.factor, &mut assembled)?;
        let t4 = Instant::now();
        let (free, c) = FreeResponse::new(
            Arc::clone(&m.factor),
            m.loads.clone(),
            basis,
            assembled,
            m.condensation.clone(),
            &m.space,
            m.kernel.clone(),
        );
        let friction = super::setup::contact_problem(&scene, &m.mesh, &m.space, c, m.kernel.as_ref())?;
        Ok(Problem {
            setup: SetupTimes { superposition: (t4 - t3).as_secs_f64(), ..SetupTimes::default() },
            reused: Some(m.times),
            scene,
            mesh: m.mesh.clone(),
            space: m.space.clone(),
            data: m.data.clone(),
            law: m.law,
            stiffness: Arc::clone(&m.stiffness),
            free,
            friction,
            errors: m.errors.clone(),
            conditioning: Arc::clone(&m.conditioning),
            step0: m.step0.clone(),
            forms: Default::default(),
        })
    }
}

/// The part of a set-up that depends on the mesh and not on the time grid: K, the loads' quadrature, the
/// factor of K, the condensation onto Γ_C, the condition estimate and step 0. The levels of a study or a
/// plan that share a mesh (same refinement, other steps) share one ([`Problem::on_shared`]), so the mesh
/// is assembled and factorised once (`study::SetupCache`).
pub struct MeshSetUp {
    mesh: Mesh,
    space: CrSpace,
    data: Option<BoundaryData>,
    law: Elasticity,
    stiffness: Arc<SparseColMat<usize, f64>>,
    loads: Loads,
    factor: Arc<Factor>,
    condensation: Option<Condensation>,
    /// The rigid motions of a floating body (`Discretised::kernel`).
    kernel: Option<Kernel>,
    conditioning: Arc<Pending>,
    errors: Option<Arc<ErrorEvaluator>>,
    step0: Option<StepResult>,
    /// The initial time the set-up was made for (step 0 depends on it).
    t0: Option<f64>,
    /// Wall times of its phases (no superposition: that is each run's own).
    times: SetupTimes,
}

impl MeshSetUp {
    /// The set-up of `scene`'s mesh (assembly, factorisation, condensation; the phases of
    /// [`Problem::new`] but the load superposition), with the condition estimate if `guard` asks for it.
    pub fn new(scene: &Scene, guard: Guard) -> Result<MeshSetUp> {
        let t0 = Instant::now();
        let mesh = Mesh::from_spec(&scene.mesh)?;
        let p0 = Discretised::new(scene.clone(), mesh, guard)?;
        let t1 = Instant::now();
        let (stiffness, loads, symbolic) = p0.assemble()?;
        let t2 = Instant::now();
        let stiffness = Arc::new(stiffness);
        let f = p0.factor(&stiffness, symbolic)?;
        let t3 = Instant::now();
        let condensation = p0.condense(&f.factor)?;
        let t5 = Instant::now();
        let Discretised { mesh, space, data, law, kernel, .. } = p0;
        let d = |a: Instant, b: Instant| (b - a).as_secs_f64();
        Ok(MeshSetUp {
            mesh,
            space,
            data,
            law,
            stiffness,
            loads,
            factor: f.factor,
            condensation,
            kernel,
            conditioning: f.conditioning,
            errors: f.errors,
            step0: f.step0,
            t0: scene.times.first().copied(),
            times: SetupTimes {
                space: d(t0, t1),
                assembly: d(t1, t2),
                factorisation: d(t2, t3),
                superposition: 0.0,
                condensation: d(t3, t5),
            },
        })
    }

    /// Unknowns of the mesh.
    pub fn unknowns(&self) -> usize {
        self.space.n_dofs
    }

    /// Bytes held: the factor's values and K (the mesh and space are a few percent of them).
    pub fn bytes(&self) -> usize {
        8 * self.factor.len_val() + 16 * self.stiffness.compute_nnz()
    }

    /// Wall times of its phases (no superposition: that is each run's own).
    pub fn times(&self) -> SetupTimes {
        self.times
    }

    /// The factor of K.
    pub fn factor(&self) -> &Factor {
        &self.factor
    }

    /// K, its lower triangle (`Problem::stiffness`).
    pub fn stiffness(&self) -> &SparseColMat<usize, f64> {
        &self.stiffness
    }
}

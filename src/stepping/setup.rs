//! The set-up of a [`Problem`] (assembly, factorisation, superposition, condensation), optionally with
//! work of the caller on a second thread beside it ([`Problem::new_beside`]: `tresca-cr run` creates its
//! results file there).

use super::conditioning::{Guard, Pending};
use super::timeline::Timeline;
use super::{initial_state, Parts, Problem, SetupTimes, StepResult};
use crate::error::{Error, Result};
use crate::fem::assemble::{stiffness_values, EdgePattern, Triangles};
use crate::fem::elasticity::Elasticity;
use crate::fem::lifting::BoundaryData;
use crate::fem::loads::Loads;
use crate::fem::norms::ErrorEvaluator;
use crate::fem::space::CrSpace;
use crate::friction::Friction;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::solve::cholesky::{fill_order_at, Factor, Symbolic};
use crate::solve::cholesky::{Graph, ND_MIN_SIZE};
use crate::solve::condense::{condense, Condensation};
use crate::solve::free::{FreeResponse, BLOCK_BYTES};
use crate::solve::kernel::Kernel;
use crate::solve::superpose::LoadBasis;
use faer::sparse::SparseColMat;
use nalgebra::DMatrix;
use std::sync::Arc;
use std::time::Instant;

/// From this many unknowns the caller's work beside the set-up starts with phase 3 ([`Discretised::set_up`]):
/// where phases 1 and 2 take seconds (1,000,000 unknowns).
const DEFER_BESIDE_MIN: usize = 1_000_000;

/// Bytes an unknown that a large run allocates after the factor besides the blocks of steps (the results
/// file's buffers, the superposition's responses, the condition estimate's vectors): measured at refine 8 of
/// Example 5.1, 0.65 GB over the factor and K less the blocks' 0.27 GB, for 1,573,376 unknowns.
const AFTER_FACTOR_BYTES: u64 = 242;

/// From this many unknowns the set-up's freed temporaries go back to the kernel before the factorisation;
/// below, they are a few MB the factor reuses, and mapping them again costs page faults (CHANGELOG.md).
const RELEASE_MIN: usize = 100_000;

/// The problem, or the set-up's error, each with the result of the work run beside the set-up.
type WithBeside<R> = std::result::Result<(Problem, Option<R>), (Error, Option<R>)>;

impl Problem {
    /// As [`Problem::new`], running `beside` on a thread of its own while the rest of the set-up
    /// (assembly, factorisation, condensation; on large meshes once the factor is made, see
    /// `Discretised::set_up`) runs: the results file is created there. `beside` sees
    /// no set-up times (they are not known yet) and its result is returned even when the set-up fails,
    /// after it (a writer then closes its file as it would have).
    pub fn new_beside<R: Send>(
        scene: Scene,
        beside: impl FnOnce(&Discretised) -> R + Send,
    ) -> (Result<Problem>, Option<R>) {
        match Mesh::from_spec(&scene.mesh) {
            Ok(mesh) => match Problem::with_mesh_beside(scene, mesh, Guard::Estimate, Some(beside)) {
                Ok((p, r)) => (Ok(p), r),
                Err((e, r)) => (Err(e), r),
            },
            Err(e) => (Err(e), None),
        }
    }

    /// [`Problem::with_mesh`] with [`Problem::new_beside`]'s second thread.
    pub(super) fn with_mesh_beside<R: Send>(
        scene: Scene,
        mesh: Mesh,
        guard: Guard,
        beside: Option<impl FnOnce(&Discretised) -> R + Send>,
    ) -> WithBeside<R> {
        let t0 = Instant::now();
        let p0 = Discretised::new(scene, mesh, guard).map_err(|e| (e, None))?;
        let t1 = Instant::now();
        let (rest, r) = p0.set_up(beside);
        let Discretised { scene, mesh, space, data, law, .. } = p0;
        let rest = match rest {
            Ok(rest) => rest,
            Err(e) => return Err((e, r)),
        };
        let Operators { stiffness, free, friction, errors, conditioning, step0, ends } = rest;
        let d = |a: Instant, b: Instant| (b - a).as_secs_f64();
        let p = Problem {
            setup: SetupTimes {
                space: d(t0, t1),
                assembly: d(t1, ends.assembly),
                factorisation: d(ends.assembly, ends.factorisation),
                superposition: d(ends.factorisation, ends.superposition),
                condensation: d(ends.superposition, ends.condensation),
            },
            reused: None,
            scene,
            mesh,
            space,
            data,
            law,
            stiffness,
            free,
            friction,
            errors,
            conditioning,
            step0,
            forms: Default::default(),
        };
        Ok((p, r))
    }
}

/// The factor and what is computed beside it.
pub(super) struct Factored {
    pub(super) factor: Arc<Factor>,
    pub(super) conditioning: Arc<Pending>,
    pub(super) errors: Option<Arc<ErrorEvaluator>>,
    pub(super) step0: Option<StepResult>,
}

/// A discretised problem, what the set-up starts from: the scene, its mesh, CR space and boundary data
/// (the lifting, added outside V_h), and the law.
/// Outside the crate it is made only by [`Discretised::new`], which validates it (`non_exhaustive`).
#[non_exhaustive]
pub struct Discretised {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    /// Nonzero boundary data u_D, g_n (`None` without).
    pub data: Option<BoundaryData>,
    pub law: Elasticity,
    /// Whether the set-up estimates K's condition number.
    pub guard: Guard,
    /// The rigid motions of a floating body (`None` with a Dirichlet part: K is nonsingular).
    pub kernel: Option<Kernel>,
}

impl Discretised {
    /// The scene on `mesh`: its parts bound and its boundary data checked (`fem::validate::on_mesh`, which
    /// every set-up passes through here, so that no command can skip it), the data's lifting and the law.
    pub fn new(scene: Scene, mesh: Mesh, guard: Guard) -> Result<Discretised> {
        let space = crate::fem::validate::on_mesh(&scene, &mesh)?;
        let data = BoundaryData::of(&mesh, &scene.parts, &space);
        let law = Elasticity::new(&scene.material);
        let kernel = Kernel::of(&mesh, &space);
        Ok(Discretised { scene, mesh, space, data, law, guard, kernel })
    }
}

/// The instants the set-up's phases ended at (the space's end and these give [`SetupTimes`]).
struct PhaseEnds {
    assembly: Instant,
    factorisation: Instant,
    superposition: Instant,
    condensation: Instant,
}

/// The operators the set-up builds from a [`Discretised`] problem, with the instants its phases ended at.
struct Operators {
    stiffness: Arc<SparseColMat<usize, f64>>,
    free: FreeResponse,
    friction: Option<Friction>,
    errors: Option<Arc<ErrorEvaluator>>,
    conditioning: Arc<Pending>,
    step0: Option<StepResult>,
    ends: PhaseEnds,
}

impl Discretised {
    /// Assembly, factorisation, superposition and condensation, in three phases:
    /// 1. K (its lower triangle: pattern and values) and the loads; beside them the ordering and the
    ///    symbolic factorisation, both from the graph of the edges (K's pattern is its expansion, so they
    ///    never wait for K; the loads stay on the main thread, so the results file's creation, beside
    ///    from the start on small meshes, keeps its share of the two cores). `TRESCA_TIMELINE` prints
    ///    the stages of both threads (`stepping::timeline`);
    /// 2. the numeric factorisation; beside it the factor's pages are mapped, then the exact solution
    ///    bound to the error quadrature and step 0 (u⁰ = I_CR u₀ with its true errors) computed;
    /// 3. the load superposition and the condensation; beside them, and beside the first steps, the
    ///    condition estimate (λ_max(K), then the solves of λ_max(K⁻¹); see `conditioning`).
    ///
    /// `beside` runs on a thread of its own, from the start below [`DEFER_BESIDE_MIN`] unknowns (on small
    /// meshes it is the longest part, for example creating the results file), else from phase 3: phases 1
    /// and 2 are where the time and the memory peak are (a third thread beside phase 1's two delays it;
    /// what it allocates beside phase 2 adds to the factor's peak: creating the results file took 0.2 s
    /// of CPU and 0.3 GB at 1.57 M unknowns). Its result is returned even when the set-up fails.
    fn set_up<R: Send, B: FnOnce(&Discretised) -> R + Send>(
        &self,
        beside: Option<B>,
    ) -> (Result<Operators>, Option<R>) {
        std::thread::scope(|s| {
            let (early, mut late) = match self.space.n_dofs < DEFER_BESIDE_MIN {
                true => (beside, None),
                false => (None, beside),
            };
            let spawn = |f: Option<B>| {
                f.map(|f| crate::threads::scoped(s, "the work beside the set-up", || f(self))).transpose()
            };
            let mut r = match spawn(early) {
                Ok(r) => r,
                Err(e) => return (Err(e), None),
            };
            let mut refused = None;
            let mut start_late = || match spawn(late.take()) {
                Ok(h) => r = h.or(r.take()),
                Err(e) => refused = Some(e),
            };
            let rest =
                self.assemble().and_then(|(k, loads, symbolic)| self.factorise(k, loads, symbolic, &mut start_late));
            // a set-up that failed before phase 3 still runs it (its result is returned)
            start_late();
            let rest = match refused {
                Some(e) => Err(e),
                None => rest,
            };
            (rest, r.map(|r| r.join().unwrap_or_else(|e| std::panic::resume_unwind(e))))
        })
    }

    /// Phase 1: K (its lower triangle), the loads and the symbolic factorisation.
    pub(super) fn assemble(&self) -> Result<(SparseColMat<usize, f64>, Loads, Symbolic)> {
        let (scene, mesh, space, law) = (&self.scene, &self.mesh, &self.space, &self.law);
        let tl = Timeline::new();
        let pattern = tl.stage("main", "edge pattern", || EdgePattern::new(mesh));
        // contact unknowns last: the condensation then comes from the factor (solve::condense)
        let contact: Vec<usize> = space.contact_dofs();
        // The ordering and the symbolic factorisation need only the graph of the edges (K's pattern is
        // its expansion: `Symbolic::from_graph`), so the second thread computes them while this one makes
        // K, without waiting for it.
        let (val, loads, symbolic, k_pattern) = std::thread::scope(|s| {
            let (pattern, contact, tl) = (&pattern, &contact, &tl);
            let symbolic = crate::threads::scoped(s, "the ordering and symbolic factorisation", move || {
                let graph = tl.stage("ordering", "graph", || {
                    let (first, start, adj) = pattern.unknown_graph(space);
                    Graph::new(first, start, adj)
                });
                let graph =
                    graph.ok_or_else(|| Error::Linear("internal: the graph of the unknowns is malformed".into()))?;
                let nested = space.n_dofs >= ND_MIN_SIZE;
                let order = tl.stage("ordering", "dissection", || {
                    fill_order_at(&graph, Some(&EdgePattern::unknown_points(mesh, space)), nested)
                })?;
                let name = if nested { "nested dissection by coordinates" } else { "AMD" };
                let symbolic = tl.stage("ordering", "symbolic", || Symbolic::from_graph(&graph, contact, order))?;
                let symbolic = symbolic.ordered_by(name);
                // on top of the factor: K's values (its lower triangle, assembled meanwhile) all along, and
                // once the factorisation's scratch is freed the blocks of steps and what else comes after it
                // ([`AFTER_FACTOR_BYTES`], the condition estimate's Lanczos vectors included)
                let n = space.n_dofs as u64;
                let (beside, after) = (8 * symbolic.pattern_nnz() as u64, AFTER_FACTOR_BYTES * n + BLOCK_BYTES);
                if !nested || symbolic.fits(beside, after) {
                    return Ok(symbolic);
                }
                // The factor of the coordinate bisection does not fit: METIS's ordering fills less
                // (about 13 % on Example 5.1 at 6.3 M unknowns) for a slower ordering (tens of seconds).
                drop(symbolic);
                Symbolic::from_graph(&graph, contact, fill_order_at(&graph, None, true)?)
                    .map(|s| s.ordered_by("METIS nested dissection (the factor by coordinates did not fit in memory)"))
            })?;
            // K is kept as its lower triangle, the one the factorisation reads (half the memory), and
            // assembled straight into it
            let k_pattern = tl.stage("main", "K's lower pattern", || pattern.unknown_pattern_lower(space));
            let val = tl.stage("main", "K's values", || {
                stiffness_values(pattern, (k_pattern.as_ref(), Triangles::Lower), mesh, space, law, scene.rho)
            });
            let loads = tl.stage("main", "loads", || Loads::new(scene, mesh, space, self.data.as_ref()))?;
            let symbolic = tl.stage("main", "join", || symbolic.join());
            let symbolic =
                symbolic.map_err(|_| Error::Linear("the symbolic factorisation failed".into())).and_then(|r| r)?;
            Ok((val, loads, symbolic, k_pattern))
        })?;
        tl.print();
        Ok((SparseColMat::new(k_pattern, val), loads, symbolic))
    }

    /// Phases 2 and 3: the factor, the superposition, the condensation, the condition estimate under way.
    /// `phase3` is called once the factor is made.
    fn factorise(
        &self,
        stiffness: SparseColMat<usize, f64>,
        loads: Loads,
        symbolic: Symbolic,
        phase3: &mut dyn FnMut(),
    ) -> Result<Operators> {
        let (scene, space) = (&self.scene, &self.space);
        let t2 = Instant::now();
        let stiffness = Arc::new(stiffness);
        let Factored { factor, conditioning, errors, step0 } = self.factor(&stiffness, symbolic)?;
        let t3 = Instant::now();
        phase3();
        let mut assembled = Vec::new();
        let basis = LoadBasis::build(&loads, &scene.times, &factor, &mut assembled)?;
        let t4 = Instant::now();
        let condensation = self.condense(&factor)?;
        let t5 = Instant::now();
        let (free, c) = FreeResponse::new(factor, loads, basis, assembled, condensation, space, self.kernel.clone());
        let friction = contact_problem(scene, &self.mesh, space, c, self.kernel.as_ref())?;
        let ends = PhaseEnds { assembly: t2, factorisation: t3, superposition: t4, condensation: t5 };
        Ok(Operators { stiffness, free, friction, errors, conditioning, step0, ends })
    }

    /// Phase 2: the numeric factorisation; beside it the error quadrature and step 0; after it the
    /// condition estimate is started on its own thread (not with [`Guard::Skip`]).
    pub(super) fn factor(&self, stiffness: &Arc<SparseColMat<usize, f64>>, symbolic: Symbolic) -> Result<Factored> {
        let (scene, mesh, space, law) = (&self.scene, &self.mesh, &self.space, &self.law);
        // the set-up's temporaries are freed: their pages go back before the factor's are mapped
        if space.n_dofs >= RELEASE_MIN {
            crate::machine::release_freed_memory();
        }
        // a floating body: K_# (the rigid motions pinned, `solve::kernel`), K itself stays a_h's matrix
        let pinned = self.kernel.as_ref().map(|k| k.pin(stiffness));
        let (factor, aside) = Factor::numeric_beside(symbolic, pinned.as_ref().unwrap_or(stiffness), || {
            let has_data = self.data.is_some();
            let errors =
                scene.exact.as_ref().map(|x| ErrorEvaluator::new(mesh, space, has_data, law, scene.rho).with_exact(x));
            let step0 = initial_state(self.parts(), stiffness, errors.as_ref()).ok();
            (errors, step0)
        });
        let factor = factor?;
        drop(pinned);
        let (errors, step0) = aside.unwrap_or((None, None));
        // A nearly singular K (ρ → 0: plain CR fails Korn's inequality; ν → ½ far beyond locking-free
        // ranges) factorises without complaint but returns meaningless displacements: it is refused
        // by the condition estimate, which runs on its own thread from here on (conditioning).
        let factor = Arc::new(factor);
        let conditioning = Arc::new(match self.guard {
            Guard::Estimate => Pending::start(&factor, stiffness),
            Guard::Skip => Pending::skipped(),
        });
        Ok(Factored { factor, conditioning, errors: errors.map(Arc::new), step0 })
    }

    fn parts(&self) -> Parts<'_> {
        Parts { scene: &self.scene, mesh: &self.mesh, space: &self.space, data: self.data.as_ref() }
    }

    /// C = EᵀK⁻¹E and W from the factor (`None` without Γ_C).
    pub(super) fn condense(&self, factor: &Factor) -> Result<Option<Condensation>> {
        let contact: Vec<usize> = self.space.contact_dofs();
        (!contact.is_empty()).then(|| condense(&contact, factor)).transpose()
    }
}

/// The friction problem on Γ_C with operator `c` (`None` without Γ_C), with the equilibrium of the rigid
/// motions of a floating body (`friction::floating`); a floating body that no contact edge can hold is
/// refused, naming its free motions.
pub(super) fn contact_problem(
    scene: &Scene,
    mesh: &Mesh,
    space: &CrSpace,
    c: Option<DMatrix<f64>>,
    kernel: Option<&Kernel>,
) -> Result<Option<Friction>> {
    let friction = c.map(|c| Friction::new(scene, mesh, space, c)).transpose()?;
    let Some(k) = kernel else {
        return Ok(friction);
    };
    let dofs = space.contact_dofs();
    match friction {
        Some(f) if !k.unseen(&dofs) => Ok(Some(f.with_floating(k.rows(&dofs), k.motions.clone()))),
        _ => Err(Error::scene(
            &scene.file,
            "boundary",
            format!(
                "no dirichlet part, and the contact parts cannot hold the body's rigid motions ({}): \
                 add a dirichlet part or a contact part that holds them",
                k.motions.names().join(", ")
            ),
        )),
    }
}

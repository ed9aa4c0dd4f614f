//! The set-up of a [`Problem`] (assembly, factorisation, superposition, condensation), optionally with
//! work of the caller on a second thread beside it ([`Problem::new_beside`]: `tresca-cr run` creates its
//! results file there).

use super::*;
use faer::sparse::SymbolicSparseColMat;

/// The problem, or the set-up's error, each with the result of the work run beside the set-up.
type WithBeside<R> = std::result::Result<(Problem, Option<R>), (Error, Option<R>)>;

impl Problem {
    /// As [`Problem::new`], running `beside` on a thread of its own while the rest of the set-up
    /// (assembly, factorisation, condensation) runs: the results file is created there. `beside` sees
    /// no set-up times (they are not known yet) and its result is returned even when the set-up fails,
    /// after it (a writer then closes its file as it would have).
    pub fn new_beside<R: Send>(
        scene: Scene,
        beside: impl FnOnce(&Discretised) -> R + Send,
    ) -> (Result<Problem>, Option<R>) {
        match Mesh::from_spec(&scene.mesh) {
            Ok(mesh) => match Problem::with_mesh_beside(scene, mesh, Some(beside)) {
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
        beside: Option<impl FnOnce(&Discretised) -> R + Send>,
    ) -> WithBeside<R> {
        let t0 = Instant::now();
        let space = CrSpace::new(&mesh, &scene.parts).map_err(|e| (e, None))?;
        crate::fem::lifting::consistency::check(&scene, &mesh, &space).map_err(|e| (e, None))?;
        let t1 = Instant::now();
        let law = Elasticity::new(&scene.material);
        let p0 = Discretised { scene, mesh, space, law };
        let (rest, r) = p0.set_up(beside);
        let Discretised { scene, mesh, space, law } = p0;
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
            scene,
            mesh,
            space,
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

/// A discretised problem, what the set-up starts from: the scene, its mesh and CR space, and the law.
pub struct Discretised {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    pub law: Elasticity,
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
    stiffness: SparseColMat<usize, f64>,
    free: FreeResponse,
    friction: Option<Friction>,
    errors: Option<ErrorEvaluator>,
    conditioning: Pending,
    step0: Option<StepResult>,
    ends: PhaseEnds,
}

impl Discretised {
    /// Assembly, factorisation, superposition and condensation, in three phases:
    /// 1. K's pattern, values and the loads; beside them the ordering (from the graph of the edges, begun
    ///    before K's pattern is made) and the symbolic factorisation (it needs only K's pattern, which is
    ///    the mesh's; the loads stay on the main thread, so the results file's creation, beside from the
    ///    start, keeps its share of the two cores);
    /// 2. the numeric factorisation; beside it the factor's pages are mapped, then λ_max(K) of the
    ///    condition estimate is computed, the exact solution bound to the error quadrature and step 0
    ///    (u⁰ = I_CR u₀ with its true errors) computed;
    /// 3. the load superposition and the condensation; beside them, and beside the first steps, the
    ///    solves of the condition estimate (see `conditioning`).
    ///
    /// `beside` runs on a thread of its own from the start (on small meshes it is the longest part, for
    /// example creating the results file); its result is returned even when the set-up fails.
    fn set_up<R: Send>(&self, beside: Option<impl FnOnce(&Discretised) -> R + Send>) -> (Result<Operators>, Option<R>) {
        std::thread::scope(|s| {
            let r = beside.map(|f| s.spawn(|| f(self)));
            let rest = self.assemble().and_then(|(k, loads, symbolic)| self.factorise(k, loads, symbolic));
            (rest, r.map(|r| r.join().unwrap_or_else(|e| std::panic::resume_unwind(e))))
        })
    }

    /// Phase 1: K, the loads and the symbolic factorisation.
    fn assemble(&self) -> Result<(SparseColMat<usize, f64>, Loads, Symbolic)> {
        let (scene, mesh, space, law) = (&self.scene, &self.mesh, &self.space, &self.law);
        let pattern = EdgePattern::new(mesh);
        // contact unknowns last: the condensation then comes from the factor (solve::condense)
        let contact: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        // The ordering needs only the graph of the edges, so the second thread starts on it before K's
        // pattern (of the unknowns) is made, which it needs only for the symbolic factorisation: that
        // thread is the longer one and ends phase 1.
        let (tx, rx) = std::sync::mpsc::sync_channel::<Arc<SymbolicSparseColMat<usize>>>(1);
        let (val, loads, symbolic, k_pattern) = std::thread::scope(|s| {
            let (pattern, contact) = (&pattern, &contact);
            let symbolic = s.spawn(move || {
                let (first, start, adj) = pattern.unknown_graph(space);
                let graph = Graph::new(first, start, adj)
                    .ok_or_else(|| Error::Linear("internal: the graph of the unknowns is malformed".into()))?;
                let order = fill_order(&graph, space.n_dofs >= ND_MIN_SIZE)?;
                let k_pattern = rx.recv().map_err(|_| Error::Linear("internal: K's pattern was not made".into()))?;
                Symbolic::new(k_pattern.as_ref().as_ref(), contact, order)
            });
            let k_pattern = Arc::new(pattern.unknown_pattern(space));
            // a thread that failed before taking it has dropped the receiver: its error is the one reported
            let _ = tx.send(Arc::clone(&k_pattern));
            let val = stiffness_values(pattern, k_pattern.as_ref().as_ref(), mesh, space, law, scene.rho);
            let loads = Loads::new(scene, mesh, space)?;
            let symbolic = symbolic
                .join()
                .map_err(|_| Error::Linear("the symbolic factorisation failed".into()))
                .and_then(|r| r)?;
            Ok((val, loads, symbolic, k_pattern))
        })?;
        // the second thread has ended, so this is the one reference left
        let k_pattern = Arc::try_unwrap(k_pattern).unwrap_or_else(|k| (*k).clone());
        Ok((SparseColMat::new(k_pattern, val), loads, symbolic))
    }

    /// Phases 2 and 3: the factor, the superposition, the condensation, the condition estimate under way.
    fn factorise(&self, stiffness: SparseColMat<usize, f64>, loads: Loads, symbolic: Symbolic) -> Result<Operators> {
        let (scene, mesh, space, law) = (&self.scene, &self.mesh, &self.space, &self.law);
        let t2 = Instant::now();
        let (factor, aside) = Factor::numeric_beside(symbolic, &stiffness, || {
            let top = condition::largest_eigenvalue(&stiffness, 12);
            let errors = scene.exact.as_ref().map(|x| ErrorEvaluator::new(mesh, space, law, scene.rho).with_exact(x));
            let step0 = initial_state(scene, mesh, space, &stiffness, errors.as_ref()).ok();
            (top, errors, step0)
        });
        let factor = factor?;
        let (top, errors, step0) = aside.unwrap_or((f64::NAN, None, None));
        let t3 = Instant::now();
        // A nearly singular K (ρ → 0: plain CR fails Korn's inequality; ν → ½ far beyond locking-free
        // ranges) factorises without complaint but returns meaningless displacements: it is refused
        // by the condition estimate, whose solves run on their own thread from here on (conditioning).
        let factor = Arc::new(factor);
        let conditioning = Pending::start(&factor, stiffness.nrows(), top);
        let mut assembled = Vec::new();
        let basis = LoadBasis::build(&loads, &scene.times, &factor, &mut assembled)?;
        let t4 = Instant::now();
        let contact: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        let condensation = (!contact.is_empty()).then(|| condense(&contact, &factor)).transpose()?;
        let t5 = Instant::now();
        let (free, c) = FreeResponse::new(factor, loads, basis, assembled, condensation, space);
        let friction = c.map(|c| Friction::new(space, c, scene.solver));
        let ends = PhaseEnds { assembly: t2, factorisation: t3, superposition: t4, condensation: t5 };
        Ok(Operators { stiffness, free, friction, errors, conditioning, step0, ends })
    }
}

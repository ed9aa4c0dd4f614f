//! The set-up of a [`Problem`] (assembly, factorisation, superposition, condensation), optionally with
//! work of the caller on a second thread beside it ([`Problem::new_beside`]: `tresca-cr run` creates its
//! results file there).

use super::*;

impl Problem {
    /// As [`Problem::new`], running `beside` on a second thread once the mesh and the space are known,
    /// while the rest of the set-up (assembly, factorisation, condensation) runs: the results file is
    /// created there. `beside` sees no set-up times (they are not known yet) and its result is returned
    /// even when the set-up fails, after it (a writer then closes its file as it would have).
    pub fn new_beside<R: Send>(
        scene: Scene,
        beside: impl FnOnce(&Problem0) -> R + Send,
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
    #[allow(clippy::type_complexity)]
    pub(super) fn with_mesh_beside<R: Send>(
        scene: Scene,
        mesh: Mesh,
        beside: Option<impl FnOnce(&Problem0) -> R + Send>,
    ) -> std::result::Result<(Problem, Option<R>), (Error, Option<R>)> {
        let t0 = Instant::now();
        let space = CrSpace::new(&mesh, &scene.parts).map_err(|e| (e, None))?;
        let t1 = Instant::now();
        let law = Elasticity::new(&scene.material);
        let p0 = Problem0 { scene, mesh, space, law };
        let (rest, r) = std::thread::scope(|s| {
            let r = beside.map(|f| s.spawn(|| f(&p0)));
            let rest = p0.set_up();
            (rest, r.map(|r| r.join().unwrap_or_else(|e| std::panic::resume_unwind(e))))
        });
        let Problem0 { scene, mesh, space, law } = p0;
        let rest = match rest {
            Ok(rest) => rest,
            Err(e) => return Err((e, r)),
        };
        let SetUp { stiffness, free, friction, errors, t2, t3, t4, t5, wait } = rest;
        let d = |a: Instant, b: Instant| (b - a).as_secs_f64();
        let p = Problem {
            setup: SetupTimes {
                space: d(t0, t1),
                assembly: d(t1, t2),
                factorisation: d(t2, t3) + wait,
                superposition: d(t3, t4),
                condensation: d(t4, t5),
            },
            scene,
            mesh,
            space,
            law,
            stiffness,
            free,
            friction,
            errors,
        };
        Ok((p, r))
    }
}

/// What the set-up starts from: the scene, its mesh and space, and the law.
pub struct Problem0 {
    pub scene: Scene,
    pub mesh: Mesh,
    pub space: CrSpace,
    pub law: Elasticity,
}

/// The rest of the set-up, with the instants its phases ended at.
struct SetUp {
    stiffness: SparseColMat<usize, f64>,
    free: FreeResponse,
    friction: Option<Friction>,
    errors: Option<ErrorEvaluator>,
    t2: Instant,
    t3: Instant,
    t4: Instant,
    t5: Instant,
    wait: f64,
}

impl Problem0 {
    /// Assembly, factorisation, superposition and condensation.
    fn set_up(&self) -> Result<SetUp> {
        let (scene, mesh, space, law) = (&self.scene, &self.mesh, &self.space, &self.law);
        // K's pattern is the mesh's: the fill-reducing ordering is computed from it on a second thread
        // while K's values and the load quadrature are assembled
        let pattern = EdgePattern::new(mesh);
        let (stiffness, loads, order) = std::thread::scope(|s| {
            let order = s.spawn(|| {
                let (first, start, adj) = pattern.unknown_graph(space);
                let graph = Graph::new(first, start, adj)
                    .ok_or_else(|| Error::Linear("internal: the graph of the unknowns is malformed".into()))?;
                fill_order(&graph, space.n_dofs >= ND_MIN_SIZE)
            });
            let stiffness = stiffness_on(&pattern, mesh, space, law, scene.rho);
            let loads = Loads::new(scene, mesh, space);
            let order = order.join().map_err(|_| Error::Linear("the fill-reducing ordering failed".into()));
            (stiffness, loads, order)
        });
        let loads = loads?;
        let t2 = Instant::now();
        // contact unknowns last: the condensation then comes from the factor (solve::condense)
        let contact: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        let factor = Factor::with_order(&stiffness, &contact, order??)?;
        let t3 = Instant::now();
        // A nearly singular K (ρ → 0: plain CR fails Korn's inequality; ν → ½ far beyond locking-free
        // ranges) factorises without complaint but returns meaningless displacements: refuse it. The
        // estimate's solves (the longer half) run on a second thread beside the load superposition and
        // the condensation, which only read the factor, and its matrix products on this thread after
        // them; nothing is returned before it is known.
        let (kappa, basis, condensation, t4, t5) = std::thread::scope(|s| {
            let (n, f) = (stiffness.nrows(), &factor);
            let inverse = s.spawn(move || condition::largest_inverse_eigenvalue(f, n, 12));
            let basis = LoadBasis::build(&loads, &scene.times, &factor);
            let t4 = Instant::now();
            let condensation = (!contact.is_empty()).then(|| condense(&contact, &factor)).transpose();
            let t5 = Instant::now();
            let top = condition::largest_eigenvalue(&stiffness, 12);
            let kappa =
                inverse.join().map(|inv| top * inv).map_err(|_| Error::Linear("the condition estimate failed".into()));
            (kappa, basis, condensation, t4, t5)
        });
        let kappa = kappa?;
        let wait = t5.elapsed().as_secs_f64();
        conditioning::check(kappa, scene, mesh, space)?;
        let (free, c) = FreeResponse::new(factor, loads, basis?, condensation?, space);
        let friction = c.map(|c| Friction::new(space, c, scene.solver));
        let errors = scene.exact.as_ref().map(|x| ErrorEvaluator::new(mesh, space, law, scene.rho).with_exact(x));
        Ok(SetUp { stiffness, free, friction, errors, t2, t3, t4, t5, wait })
    }
}

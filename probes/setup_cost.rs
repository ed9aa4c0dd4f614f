//! Single-thread cost of each stage of a run's set-up (median of PASSES passes, default 7), the numbers
//! behind the schedule of `stepping::setup` (which stages run beside which), with the sizes of K and of
//! its factor. Each stage is timed by the thread's CPU clock (the machine is shared: wall times carry
//! the other processes' load) with its minor page faults (K kept and factorised as its lower triangle, as
//! a run does); ORDERING is `auto` (the run's choice: nested
//! dissection by coordinates from `ND_MIN_SIZE` unknowns), `amd`, `nd` (by coordinates) or `metis`.
//!
//! `RAYON_NUM_THREADS=1 cargo run --release --example setup_cost verification/cases/mms_stop.toml 4 [PASSES] [ORDERING] [symbolic]`
//!
//! A fifth argument `symbolic` stops each pass after the symbolic factorisation: the size of K and of its
//! factor for meshes whose numeric factorisation does not fit in memory.
//!
//! In a real run every buffer is fresh memory, whose first touch costs about 2.4 µs a page on the
//! project's VMs; from the second pass on the allocator reuses memory, so these are compute costs.
use tresca_cr::fem::assemble::{stiffness_values, EdgePattern, Triangles};
use tresca_cr::fem::elasticity::Elasticity;
use tresca_cr::fem::lifting::BoundaryData;
use tresca_cr::fem::loads::Loads;
use tresca_cr::fem::norms::ErrorEvaluator;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::Mesh;
use tresca_cr::solve::cholesky::Graph;
use tresca_cr::solve::cholesky::{fill_order_at, Factor, Symbolic};
use tresca_cr::Scene;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mut scene = Scene::from_file(std::path::Path::new(&a[0])).unwrap();
    scene.set_refine(a[1].parse().unwrap()).unwrap();
    let passes: usize = a.get(2).map_or(7, |p| p.parse().unwrap());
    let n_est = tresca_cr::scene::budget::Estimate::of(&scene, 1, false).unwrap().unknowns as usize;
    let nested = match a.get(3).map_or("auto", |s| s.as_str()) {
        "auto" => n_est >= tresca_cr::solve::cholesky::ND_MIN_SIZE,
        "nd" | "metis" => true,
        "amd" => false,
        o => panic!("ordering `{o}`: auto, amd, nd (by coordinates) or metis"),
    };
    let metis = a.get(3).is_some_and(|s| s == "metis");
    let symbolic_only = a.get(4).is_some_and(|s| s == "symbolic");
    let mut rows: Vec<(&str, Vec<(f64, f64)>)> = Vec::new();
    let mut tm = |name: &'static str, d: (f64, f64)| match rows.iter_mut().find(|r| r.0 == name) {
        Some(r) => r.1.push(d),
        None => rows.push((name, vec![d])),
    };
    let mut sizes = (0, 0, 0.0, 0);
    for _ in 0..passes {
        let t = Clock::now();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        tm("mesh", t.elapsed());
        let t = Clock::now();
        let space = CrSpace::new(&mesh, &scene.parts).unwrap();
        let data = BoundaryData::of(&mesh, &scene.parts, &space);
        tm("space", t.elapsed());
        let law = Elasticity::new(&scene.material);
        let t = Clock::now();
        let pattern = EdgePattern::new(&mesh);
        tm("edge pattern", t.elapsed());
        let t = Clock::now();
        let (f, s, adj) = pattern.unknown_graph(&space);
        let graph = Graph::new(f, s, adj).unwrap();
        tm("graph", t.elapsed());
        let t = Clock::now();
        let points = (!metis).then(|| EdgePattern::unknown_points(&mesh, &space));
        let order = fill_order_at(&graph, points.as_deref(), nested).unwrap();
        tm(if nested { "nested dissection" } else { "amd" }, t.elapsed());
        let contact: Vec<usize> = space.contact_dofs();
        let t = Clock::now();
        let sym = Symbolic::from_graph(&graph, &contact, order).unwrap();
        tm("symbolic", t.elapsed());
        sizes = (sym.pattern_nnz(), sym.len_val(), sym.flops_and_entries().0, sym.n_supernodes());
        if symbolic_only {
            continue;
        }
        let t = Clock::now();
        let lower = pattern.unknown_pattern_lower(&space);
        tm("lower pattern", t.elapsed());
        let t = Clock::now();
        let val = stiffness_values(&pattern, (lower.as_ref(), Triangles::Lower), &mesh, &space, &law, scene.rho);
        tm("stiffness", t.elapsed());
        let k = faer::sparse::SparseColMat::new(lower, val);
        let t = Clock::now();
        let loads = Loads::new(&scene, &mesh, &space, data.as_ref()).unwrap();
        tm("loads", t.elapsed());
        let t = Clock::now();
        let factor = Factor::numeric(sym, &k).unwrap();
        tm("numeric", t.elapsed());
        let t = Clock::now();
        let top = tresca_cr::solve::condition::largest_eigenvalue(&k, 12);
        tm("lambda_max", t.elapsed());
        let t = Clock::now();
        let inv = tresca_cr::solve::condition::largest_inverse_eigenvalue(&factor, k.nrows(), 12);
        tm("inverse", t.elapsed());
        let t = Clock::now();
        let ev = scene
            .exact
            .as_ref()
            .map(|x| ErrorEvaluator::new(&mesh, &space, data.is_some(), &law, scene.rho).with_exact(x));
        tm("error evaluator", t.elapsed());
        std::hint::black_box((loads, top, inv, ev));
    }
    println!(
        "entries of K's lower triangle {}, of its factor {}; flops Σ c² {:.4e}; supernodes {}",
        sizes.0, sizes.1, sizes.2, sizes.3
    );
    println!("{:>17} {:>11} {:>12} {:>11}", "stage", "CPU", "minor faults", "CPU min");
    for (name, mut v) in rows {
        v.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (cpu, faults) = v[v.len() / 2];
        println!("{name:>17} {:8.2} ms {faults:12.0} {:8.2} ms", cpu * 1e3, v[0].0 * 1e3);
    }
}

/// The thread's CPU time and minor page faults at a point, for the stage that starts there.
struct Clock(f64, f64);

impl Clock {
    fn read() -> (f64, f64) {
        // SAFETY: a plain system call filling the struct given.
        let ru = unsafe {
            let mut ru: libc::rusage = std::mem::zeroed();
            libc::getrusage(libc::RUSAGE_THREAD, &mut ru);
            ru
        };
        (tresca_cr::machine::thread_cpu_seconds(), ru.ru_minflt as f64)
    }
    fn now() -> Clock {
        let (c, f) = Clock::read();
        Clock(c, f)
    }
    /// (CPU seconds, minor faults) since `now`.
    fn elapsed(&self) -> (f64, f64) {
        let (c, f) = Clock::read();
        (c - self.0, f - self.1)
    }
}

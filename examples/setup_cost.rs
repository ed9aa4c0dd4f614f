//! Single-thread cost of each stage of a run's set-up (median of 7 passes), the numbers behind the
//! schedule of `stepping::setup` (which stages run beside which), with the sizes of K and of its factor.
//!
//! `RAYON_NUM_THREADS=1 cargo run --release --example setup_cost verification/cases/mms_stop.toml 4`
//!
//! In a real run every buffer is fresh memory, whose first touch costs about 2.4 µs a page on the
//! project's VMs; from the second pass on the allocator reuses memory, so these are compute costs.
use std::time::Instant;
use tresca_cr::fem::assemble::{stiffness_values, EdgePattern};
use tresca_cr::fem::elasticity::Elasticity;
use tresca_cr::fem::loads::Loads;
use tresca_cr::fem::norms::ErrorEvaluator;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::Mesh;
use tresca_cr::solve::factor::{fill_order, Factor, Symbolic};
use tresca_cr::solve::ordering::Graph;
use tresca_cr::Scene;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mut scene = Scene::from_file(std::path::Path::new(&a[0])).unwrap();
    scene.set_refine(a[1].parse().unwrap()).unwrap();
    let mut rows: Vec<(&str, Vec<f64>)> = Vec::new();
    let mut tm = |name: &'static str, d: f64| match rows.iter_mut().find(|r| r.0 == name) {
        Some(r) => r.1.push(d),
        None => rows.push((name, vec![d])),
    };
    let mut sizes = (0, 0);
    for _ in 0..7 {
        let t = Instant::now();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        tm("mesh", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let space = CrSpace::new(&mesh, &scene.parts).unwrap();
        tm("space", t.elapsed().as_secs_f64());
        let law = Elasticity::new(&scene.material);
        let t = Instant::now();
        let pattern = EdgePattern::new(&mesh);
        tm("edge pattern", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let (f, s, adj) = pattern.unknown_graph(&space);
        let graph = Graph::new(f, s, adj).unwrap();
        tm("graph", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let order = fill_order(&graph, false).unwrap();
        tm("amd", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let pat = pattern.unknown_pattern(&space);
        tm("unknown pattern", t.elapsed().as_secs_f64());
        let contact: Vec<usize> = space.contact.iter().map(|c| c.dof).collect();
        let t = Instant::now();
        let sym = Symbolic::new(pat.as_ref(), &contact, order).unwrap();
        tm("symbolic", t.elapsed().as_secs_f64());
        sizes = (pat.compute_nnz(), sym.len_val());
        let t = Instant::now();
        let val = stiffness_values(&pattern, pat.as_ref(), &mesh, &space, &law, scene.rho);
        tm("stiffness", t.elapsed().as_secs_f64());
        let k = faer::sparse::SparseColMat::new(pat, val);
        let t = Instant::now();
        let loads = Loads::new(&scene, &mesh, &space).unwrap();
        tm("loads", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let factor = Factor::numeric(sym, &k).unwrap();
        tm("numeric", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let top = tresca_cr::solve::condition::largest_eigenvalue(&k, 12);
        tm("lambda_max", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let inv = tresca_cr::solve::condition::largest_inverse_eigenvalue(&factor, k.nrows(), 12);
        tm("inverse", t.elapsed().as_secs_f64());
        let t = Instant::now();
        let ev = scene.exact.as_ref().map(|x| ErrorEvaluator::new(&mesh, &space, &law, scene.rho).with_exact(x));
        tm("error evaluator", t.elapsed().as_secs_f64());
        std::hint::black_box((loads, top, inv, ev));
    }
    println!("entries of K {}, of its factor {}", sizes.0, sizes.1);
    for (name, mut v) in rows {
        v.sort_by(f64::total_cmp);
        println!("{name:>16} {:8.2} ms", v[v.len() / 2] * 1e3);
    }
}

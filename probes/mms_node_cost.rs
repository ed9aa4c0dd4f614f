//! Per-time-node cost of what a manufactured-solution run evaluates at every time node: the load vector
//! (`Loads::assemble_on_support`: f and the tractions at their quadrature points) and the true error
//! norms (`ErrorEvaluator::errors`: the exact u and ∇u at the triangle points). Set-up (quadrature points,
//! binding) is timed apart. Prints one JSON line per case; median of 5 passes over all time nodes.
//!
//! `RAYON_NUM_THREADS=1 cargo run --release --example mms_node_cost [SCENE REFINE STEPS]...`
//! `loads_unseparated` is the same load with every term evaluated at every node (`Loads::with_separation`
//! with `false`), the route of scenes whose loads do not separate.
//! (default: mms_stop r4/16 and r5/64, mms_front r2/256, mms_rotated r3/16, bench_mms_poly r0/16, its own 256×128 mesh).
//! Wall and CPU (user + system, all threads) milliseconds per node.

use std::time::Instant;
use tresca_cr::fem::elasticity::Elasticity;
use tresca_cr::fem::lifting::BoundaryData;
use tresca_cr::fem::loads::Loads;
use tresca_cr::fem::norms::ErrorEvaluator;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::Mesh;
use tresca_cr::Scene;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cases: Vec<(String, u32, usize)> = if args.is_empty() {
        [
            ("verification/cases/mms_stop.toml", 4, 16),
            ("verification/cases/mms_stop.toml", 5, 64),
            ("verification/cases/mms_front.toml", 2, 256),
            ("verification/cases/mms_rotated.toml", 3, 16),
            ("verification/bench/bench_mms_poly.toml", 0, 16),
        ]
        .iter()
        .map(|&(s, r, n)| (s.to_string(), r, n))
        .collect()
    } else {
        args.chunks(3).map(|c| (c[0].clone(), c[1].parse().unwrap(), c[2].parse().unwrap())).collect()
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    for (file, refine, steps) in cases {
        let mut scene = Scene::from_file(&root.join(&file)).unwrap();
        scene.set_refine(refine).unwrap();
        scene.set_steps(steps).unwrap();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        let space = CrSpace::new(&mesh, &scene.parts).unwrap();
        let data = BoundaryData::of(&mesh, &scene.parts, &space);
        let law = Elasticity::new(&scene.material);
        let t0 = Instant::now();
        let loads = Loads::new(&scene, &mesh, &space, data.as_ref()).unwrap();
        let direct = Loads::with_separation(&scene, &mesh, &space, data.as_ref(), false).unwrap();
        let exact = scene.exact.clone().unwrap();
        let ev = ErrorEvaluator::new(&mesh, &space, data.is_some(), &law, scene.rho).with_exact(&exact);
        let setup = t0.elapsed().as_secs_f64();
        let mid = vec![[0.0; 2]; mesh.edges.len()];
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let (mut l, mut e, mut lc, mut ec, mut sink) = (Vec::new(), Vec::new(), Vec::new(), Vec::new(), 0.0);
        let mut ld = Vec::new();
        let mut out = Vec::new();
        let n = scene.times.len() as f64;
        for _ in 0..5 {
            let (t0, c0) = (Instant::now(), cpu_seconds());
            for &t in &scene.times {
                loads.assemble_on_support(t, &mut out).unwrap();
                sink += out[0];
            }
            let (t1, c1) = (Instant::now(), cpu_seconds());
            for &t in &scene.times {
                sink += ev.errors(&mesh, &exact, &mid, t).unwrap().l2;
            }
            let t2 = Instant::now();
            for &t in &scene.times {
                direct.assemble_on_support(t, &mut out).unwrap();
                sink += out[0];
            }
            ld.push(t2.elapsed().as_secs_f64() / n);
            l.push((t1 - t0).as_secs_f64() / n);
            e.push((t2 - t1).as_secs_f64() / n);
            lc.push((c1 - c0) / n);
            ec.push((cpu_seconds() - c1) / n);
        }
        println!(
            "{{\"scene\": \"{file}\", \"refine\": {refine}, \"steps\": {steps}, \"triangles\": {}, \"setup_ms\": {:.2}, \"loads_ms_per_node\": {:.3}, \"loads_unseparated_ms_per_node\": {:.3}, \"errors_ms_per_node\": {:.3}, \"loads_cpu_ms_per_node\": {:.3}, \"errors_cpu_ms_per_node\": {:.3}, \"sink\": {}}}",
            mesh.tris.len(),
            setup * 1e3,
            median(l) * 1e3,
            median(ld) * 1e3,
            median(e) * 1e3,
            median(lc) * 1e3,
            median(ec) * 1e3,
            sink.is_finite()
        );
    }
}

/// CPU time of the process (user + system, all threads), seconds.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage only writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

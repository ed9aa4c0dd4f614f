//! Points per second, on one core, of the longest expression of `verification/cases/`: exmex's
//! interpreter (the parsed expression evaluated point by point) against the compiled program (batches of points), and the
//! compiled program bound to the points (spatial part cached, as runs evaluate loads and exact solutions).
//! Run by `verification/bench/report.py` as `RAYON_NUM_THREADS=1 cargo run --release --example expr_throughput`;
//! prints one JSON line. Median of 5 timings each.

use std::time::Instant;
use tresca_cr::scene::expr::{Expr, ExprSet};

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut longest = (String::new(), String::new(), String::new());
    let mut files: Vec<_> = std::fs::read_dir(&dir).expect("verification/cases").map(|e| e.unwrap().path()).collect();
    files.sort();
    for f in files.iter().filter(|p| p.extension().is_some_and(|e| e == "toml")) {
        let text = std::fs::read_to_string(f).unwrap();
        // every quoted string of an expression-valued key is a candidate; keep the longest
        for line in text.lines().filter(|l| !l.trim_start().starts_with('#')) {
            for (i, s) in line.split('"').enumerate() {
                if i % 2 == 1 && s.len() > longest.2.len() && Expr::parse("k", s).is_ok() {
                    longest = (
                        f.file_name().unwrap().to_string_lossy().into(),
                        line.split('=').next().unwrap().trim().into(),
                        s.into(),
                    );
                }
            }
        }
    }
    let e = Expr::parse("longest", &longest.2).unwrap();
    let interp = e.interpreted().unwrap();
    let set = ExprSet::new(&[&e]);
    let n = 200_000;
    let pts: Vec<[f64; 2]> = (0..n).map(|i| [(i % 997) as f64 / 997.0, (i % 991) as f64 / 991.0]).collect();
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut sink = 0.0;
    let old = median(
        (0..5)
            .map(|_| {
                let t0 = Instant::now();
                for p in &pts[..n / 10] {
                    sink += interp.eval(p[0], p[1], 0.3);
                }
                (n / 10) as f64 / t0.elapsed().as_secs_f64()
            })
            .collect(),
    );
    let mut out = Vec::new();
    let new = median(
        (0..5)
            .map(|_| {
                let t0 = Instant::now();
                set.eval(&pts, 0.3, &mut out).unwrap();
                n as f64 / t0.elapsed().as_secs_f64()
            })
            .collect(),
    );
    sink += out[0];
    // bound to the points as runs use it: the spatial part evaluated once, each time only the rest
    let bound = set.clone().bind(pts.clone());
    let timed = median(
        (0..5)
            .map(|_| {
                let t0 = Instant::now();
                bound.eval(0.3, &mut out).unwrap();
                n as f64 / t0.elapsed().as_secs_f64()
            })
            .collect(),
    );
    sink += out[0];
    let p = set.program();
    println!(
        "{{\"file\": \"{}\", \"key\": \"{}\", \"chars\": {}, \"instructions\": {}, \"timed_instructions\": {}, \"cached_values\": {}, \"interpreted_points_per_s\": {old:.4e}, \"compiled_points_per_s\": {new:.4e}, \"bound_points_per_s\": {timed:.4e}, \"speedup\": {:.1}, \"sink\": {}}}",
        longest.0, longest.1, longest.2.len(), set.n_instructions(), p.n_timed_instructions(), p.n_cached(), new / old, sink.is_finite()
    );
}

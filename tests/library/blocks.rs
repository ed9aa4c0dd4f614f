//! Steps solved in blocks (`solve::free::Block`): a run resumed at any step reproduces the full run's
//! numbers bit for bit (blocks are aligned to step numbers), and blocked steps agree with steps solved
//! one at a time (`Problem::step`) to rounding.

use tresca_cr::{Problem, Scene, StepResult};

fn collect(p: &Problem, from: Option<StepResult>) -> Vec<StepResult> {
    let mut out = Vec::new();
    let keep = |r: &StepResult| {
        out.push(r.clone());
        Ok(())
    };
    match from {
        Some(f) => p.run(tresca_cr::RunOptions::after(f), keep).unwrap(),
        None => p.run(tresca_cr::RunOptions::all(), keep).unwrap(),
    }
    out
}

fn rel(a: &[f64], b: &[f64]) -> f64 {
    let m = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / m
}

#[test]
fn assembled_loads_resumed_and_step_by_step_match_the_blocked_run() {
    // the benchmark's loads span 5 time patterns: every step assembles and solves
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/verification/bench/bench_mms_poly.toml");
    let text = std::fs::read_to_string(path).unwrap().replace("cells    = [256, 128]", "cells    = [16, 8]");
    let mut s = Scene::from_str(&text, path).unwrap();
    s.set_steps(40).unwrap();
    let p = Problem::new(s).unwrap();
    assert!(!p.free.superposed());
    check(&p);
}

#[test]
fn superposed_loads_resumed_and_step_by_step_match_the_blocked_run() {
    // slips, then sticks from t = 1/3 on: μ repeats, then changes at every step
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/verification/cases/mms_stop.toml");
    let mut s = Scene::from_file(std::path::Path::new(path)).unwrap();
    s.set_refine(1).unwrap();
    s.set_steps(40).unwrap();
    let p = Problem::new(s).unwrap();
    assert!(p.free.superposed());
    check(&p);
}

fn check(p: &Problem) {
    assert!(p.free.block_size() > 1, "the scene must take the blocked path");
    let full = collect(p, None);
    assert_eq!(full.len(), 41);
    for from in [1, 13, 16, 17, 39] {
        let resumed = collect(p, Some(full[from].clone()));
        for (a, b) in full[from + 1..].iter().zip(&resumed) {
            assert_eq!(a.n, b.n);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&a.u), bits(&b.u), "u at step {} resumed from {from}", a.n);
            assert_eq!(bits(&a.mu), bits(&b.mu), "mu at step {} resumed from {from}", a.n);
            assert_eq!(a.energy.to_bits(), b.energy.to_bits());
        }
    }
    let mut prev = full[0].clone();
    let mut load = Vec::new();
    for a in &full[1..] {
        let r = p.step(a.n, &prev, &mut load, true).unwrap();
        assert!(rel(&a.u, &r.u) < 1e-12 && rel(&a.slip, &r.slip) < 1e-12, "step {}", a.n);
        prev = r;
    }
}

//! The adaptive loop (src/adapt): the indicator vanishes where u_h is exact, its effectivity stays in
//! a bounded range, adaptive meshes converge at the optimal DOF^(-1/2) where uniform ones cannot, and
//! `tresca-cr adapt` writes its files and refuses what does not fit.

mod common;

use common::{fitted_rate, scene, successive_rates};
use std::process::Command;
use tresca_cr::adapt::estimator::Estimator;
use tresca_cr::adapt::{adapt, Options, Row};
use tresca_cr::{Problem, Scene};

fn options(levels: usize, theta: f64, reference: Option<u32>) -> Options {
    Options { reference, ..Options::levels(levels, theta) }
}

fn rows(s: &Scene, o: &Options) -> Vec<Row> {
    adapt(s, o, |_| {}).unwrap().rows
}

/// Orders in DOF⁻¹ of (unknowns, error) rows.
fn rates(rows: &[Row], err: impl Fn(&Row) -> f64) -> (f64, Vec<f64>) {
    let x: Vec<f64> = rows.iter().map(|r| 1.0 / r.unknowns as f64).collect();
    let e: Vec<f64> = rows.iter().map(err).collect();
    (fitted_rate(&x, &e), successive_rates(&x, &e))
}

/// u = (a x t, 0) on the unit square: clamped at x = 0, the exact tractions σ(u)n on the right and top,
/// frictionless contact on the bottom (σ_τ = 0 there, u_n = 0). Affine, so every u_h is I_CR u = u.
const AFFINE: &str = r#"
title = "affine"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [3, 3]
diagonal = "first"
[material]
E = 100.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
[[boundary]]
name = "right"
kind = "neumann"
traction = ["(100*0.3/(1.3*0.4) + 100/1.3)*0.01*t", "0"]
[[boundary]]
name = "top"
kind = "neumann"
traction = ["0", "100*0.3/(1.3*0.4)*0.01*t"]
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0"
[time]
T = 1.0
steps = 3
[solver]
method = "ssn"
tol = 1e-12
"#;

/// The system shall give an indicator that vanishes (to rounding) when u_h is the exact solution: every
/// term — stress jumps, Neumann residual, friction mismatch, jumps — is zero for an affine u.
#[test]
fn indicator_vanishes_on_an_exact_discrete_solution() {
    indicator_vanishes_on(AFFINE);
}

/// The system shall measure the indicator of a scene with Dirichlet data on the full displacement
/// (unknowns plus the lifting of u_D) and its Dirichlet jumps against u_D: for u = (a t (x + 1/2), 0),
/// u_D = a t/2 on x = 0, the indicator vanishes to rounding as for u_D = 0 (the unknowns alone, or a jump
/// against 0, would leave terms of size |u_D|²/h).
#[test]
fn indicator_vanishes_on_an_exact_discrete_solution_with_dirichlet_data() {
    let with_data = AFFINE.replace("kind = \"dirichlet\"", "kind = \"dirichlet\"\nu = [\"0.005*t\", \"0\"]");
    assert_ne!(with_data, AFFINE);
    indicator_vanishes_on(&with_data);
}

/// The system shall measure levels of a scene with Dirichlet data against the reference by their full
/// displacements (unknowns plus the lifting of u_D), Dirichlet jumps against u_D. Uniform levels 0–5 of
/// mms_data_front with the reference at generation 6, level 5's mesh bisected once more: with G the broken
/// gradient part and J(u_l) the jump part common to both measures, error = ‖(G(u − u_l), J)‖ and
/// vs_reference = ‖(G(u_ref − u_l), J)‖, so |vs_reference − error| ≤ G(u − u_ref) ≤ error(reference) ≤
/// error(level 5) (the triangle inequality, then the error decreasing under uniform refinement; rounding
/// 1e-12 beside). The unknowns alone would compare w, not u: about 4, ~30× the error.
#[test]
fn reference_distances_with_dirichlet_data_track_the_true_error() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases/mms_data_front.toml");
    let text = std::fs::read_to_string(path).unwrap().replace("steps = 64", "steps = 8");
    let s = Scene::from_str(&text, "mms_data_front.toml").unwrap();
    let rs = rows(&s, &options(6, 1.0, Some(6)));
    let bound = rs[5].error.unwrap() + 1e-12;
    for r in &rs {
        let (d, e) = (r.vs_reference.unwrap(), r.error.unwrap());
        println!("level {}: vs reference {d:.6e}, error {e:.6e}, bound {bound:.3e}", r.level);
        assert!((d - e).abs() <= bound, "level {}: vs reference {d} against error {e}", r.level);
    }
}

fn indicator_vanishes_on(text: &str) {
    let p = Problem::new(Scene::from_str(text, "affine.toml").unwrap()).unwrap();
    let est = Estimator::new(&p).unwrap();
    let mut steps = Vec::new();
    p.run(tresca_cr::RunOptions::all(), |r: &tresca_cr::StepResult| {
        steps.push(r.clone());
        Ok(())
    })
    .unwrap();
    assert_eq!(steps.len(), 4);
    for r in steps.iter().filter(|r| r.n > 0) {
        let ind = est.at(&p, r).unwrap();
        // the scale: |||u_h||| = a_h(u_h, u_h)^{1/2}; rounding of σ_T (assembled from 3 edge values of
        // size 1e-2 with gradients of size 1/h) leaves relative residuals of ~1e-13
        let scale = r.energy.sqrt();
        assert!(scale > 1e-3, "the load moves the body");
        assert!(ind.global() <= 1e-10 * scale, "step {}: η = {:e} vs |||u_h||| = {scale:e}", r.n, ind.global());
    }
}

/// The system shall keep the effectivity η/|||u − u_h||| in a bounded range over the adapted levels of
/// manufactured solutions, with and without friction, and converge at the optimal rate DOF^(-1/2).
/// Reliability and efficiency give c ≤ η/|||e||| ≤ C with constants that are not known; the test asks
/// for η ≥ |||e||| (measured ≥ 4.9) and a range max/min ≤ 1.5 (measured 1.21 and 1.07 over 16 levels).
/// The rate: a least-squares fit over the last 8 levels (DOF ×10) within 0.05 of 1/2, and the orders
/// over windows of 3 levels (levels 4, 7, …, 16: DOF ×2.2–2.4 each) within 0.12 of it. (Dörfler's
/// greedy marking lets a level's error sit ±5 % off the trend — per level, DOF ×1.3, that swings
/// single orders by 0.3, measured 0.34–0.83 — and ±5 % at both ends of a ×2.3 window moves its order
/// by ln(1.05²)/ln 2.3 = 0.12.)
#[test]
fn effectivity_is_bounded_and_adaptive_rate_is_optimal_on_manufactured_cases() {
    for case in ["verification/cases/mms_elastic.toml", "verification/cases/mms_stick_to_slip.toml"] {
        let rs = rows(&scene(case), &options(17, 0.5, None));
        let eff: Vec<f64> = rs.iter().map(|r| r.estimator / r.error.unwrap()).collect();
        let (lo, hi) = eff.iter().fold((f64::INFINITY, 0.0f64), |(a, b), &e| (a.min(e), b.max(e)));
        println!("{case}: effectivity {lo:.3}..{hi:.3}");
        assert!(lo >= 1.0 && hi / lo <= 1.5, "{case}: effectivity {eff:?}");
        let (fit, _) = rates(&rs[9..], |r| r.error.unwrap());
        let windows: Vec<Row> = rs.iter().skip(4).step_by(3).cloned().collect();
        let (_, local) = rates(&windows, |r| r.error.unwrap());
        println!("{case}: rate {fit:.3}, over 3-level windows {local:?}");
        assert!((fit - 0.5).abs() <= 0.05, "{case}: fitted rate {fit}");
        assert!(local.len() >= 4 && local.iter().all(|o| (o - 0.5).abs() <= 0.12), "{case}: rates {local:?}");
        assert!(rs.iter().all(|r| (r.min_angle - 45.0).abs() < 1e-9), "structured meshes keep 45°");
    }
}

/// The system shall, on Example 5.1 (no exact solution; errors against one reference solution of
/// bisection generation 11, nested in every level of both routes), converge adaptively at DOF^(-1/2)
/// where uniform refinement gives about DOF^(-0.43) (the corner singularities), and need fewer DOF for
/// the same error. Levels up to about a quarter of the reference's DOF only, so the reference's own
/// error (about half of theirs) shifts their errors by ≲ 12 % (|||u − u_l|||² ≈ |||u_ref − u_l|||² +
/// |||u − u_ref|||² on nested meshes): rates within 0.05.
#[test]
fn example_5_1_adaptive_beats_uniform_against_a_reference() {
    let s = scene("verification/cases/paper_example_5_1.toml");
    let adaptive = rows(&s, &options(16, 0.5, Some(11)));
    let uniform = rows(&s, &options(9, 1.0, Some(11)));
    let e = |r: &Row| r.vs_reference.unwrap();
    let (ra, la) = rates(&adaptive[6..], e);
    let (ru, lu) = rates(&uniform[3..], e);
    println!("adaptive rate {ra:.3} {la:?}\nuniform rate {ru:.3} {lu:?}");
    assert!((ra - 0.5).abs() <= 0.05, "adaptive rate {ra}");
    assert!((ru - 0.43).abs() <= 0.05, "uniform rate {ru}");
    // the same error with fewer unknowns: the adaptive level just below the finest uniform level's error
    let target = e(uniform.last().unwrap());
    let need = adaptive.iter().find(|r| e(r) <= target).expect("adaptive reaches the finest uniform error");
    println!("error {target:.3e}: adaptive {} unknowns, uniform {}", need.unknowns, uniform.last().unwrap().unknowns);
    assert!(need.unknowns < uniform.last().unwrap().unknowns);
    let eff: Vec<f64> = adaptive.iter().map(|r| r.estimator / e(r)).collect();
    assert!(eff.iter().all(|&x| x >= 1.0), "reliable: {eff:?}");
}

/// The system shall stop the loop at the first level with at least `until_unknowns` unknowns, and in
/// lean mode (a planner's pilot) compute the same η, meshes, distances and error estimates as the full
/// loop without the time indicator (counted: the field stays 0).
#[test]
fn lean_loop_stops_at_its_unknowns_and_gives_the_full_loops_indicator() {
    let s = scene("verification/cases/paper_example_5_1.toml");
    let full = rows(&s, &options(12, 0.5, None));
    let until = full[8].unknowns;
    let lean = rows(&s, &Options { until_unknowns: Some(until), lean: true, ..options(12, 0.5, None) });
    assert_eq!(lean.len(), 9, "stops at level 8, the first with {until} unknowns");
    for (f, l) in full.iter().zip(&lean) {
        assert_eq!((f.unknowns, f.estimator.to_bits()), (l.unknowns, l.estimator.to_bits()), "level {}", f.level);
        assert!(l.time_estimator == 0.0, "level {}: {l:?}", l.level);
        assert_eq!(f.estimate.map(f64::to_bits), l.estimate.map(f64::to_bits), "level {}", f.level);
    }
    assert!(full[..8].iter().all(|r| r.vs_next.is_some() && r.time_estimator > 0.0));
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_tresca-cr"))
}

/// The system shall write DIR/level_<k>.h5 and the CSV of `tresca-cr adapt`, and refuse with the reason
/// (exit code 3) a level that does not fit the memory given, and refuse a bad θ with one error line.
#[test]
fn adapt_command_writes_levels_and_refuses_what_does_not_fit() {
    let dir = std::env::temp_dir().join(format!("tresca_adapt_test_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let sc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases/lshape_adapt.toml");
    let csv = dir.as_path().join("a.csv");
    let out = bin()
        .args(["adapt", sc.to_str().unwrap(), "--levels", "3", "--steps", "2", "--csv", csv.to_str().unwrap()])
        .arg("--out")
        .arg(dir.as_path().join("levels"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    for k in 0..3 {
        assert!(dir.as_path().join(format!("levels/level_{k}.h5")).is_file(), "level_{k}.h5");
    }
    let text = std::fs::read_to_string(&csv).unwrap();
    let head: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    for col in ["level", "unknowns", "estimator", "error", "effectivity", "min_angle_deg", "wall_s"] {
        assert!(head.contains(&col), "column {col} in {head:?}");
    }
    assert_eq!(text.lines().count(), 4);
    let json = dir.as_path().join("a.json");
    let out = bin()
        .args(["adapt", sc.to_str().unwrap(), "--target", "1e-9", "--max-memory", "40M", "--json"])
        .arg(&json)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(err.contains("does not fit") && err.contains("memory"), "{err}");
    // the summary of a refused loop: the levels that ran, and why it stopped
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["command"], "adapt");
    assert!(v["status"].as_str().unwrap().starts_with("refused: level"), "{v}");
    let levels = v["adapt"]["levels"].as_array().unwrap();
    assert!(!levels.is_empty() && levels[0]["unknowns"].as_u64().unwrap() > 0, "{v}");
    assert!(levels.iter().all(|l| l["estimator"].as_f64().unwrap() > 1e-9), "stopped before the target");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The system shall refuse each bad value of `adapt`'s flags with one error naming the flag and what it
/// takes, and a non-zero exit, before any level is solved (no panic, nothing written).
#[test]
fn adapt_refuses_bad_flags_naming_them() {
    let sc = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases/lshape_adapt.toml");
    let bad: [(&[&str], &str); 12] = [
        (&["--levels", "2", "--theta", "1.5"], "(0, 1]"),
        (&["--levels", "2", "--theta", "0"], "(0, 1]"),
        (&["--levels", "2", "--theta", "-0.5"], "(0, 1]"),
        (&["--levels", "0"], "≥ 1"),
        (&["--levels", "-3"], "≥ 1"),
        (&["--target", "0"], "> 0"),
        (&["--target", "-1e-3"], "> 0"),
        (&["--target", "nan"], "> 0"),
        (&["--levels", "2", "--refine", "-1"], "refinements"),
        (&["--levels", "2", "--steps", "-4"], "whole number"),
        (&["--levels", "2", "--reference", "99"], "at most 24"),
        (&["--levels", "2", "--budget", "-5s"], "positive duration"),
    ];
    let flag = |args: &[&str]| args.iter().rev().nth(1).unwrap().to_string();
    for (args, what) in bad {
        let out = bin().arg("adapt").arg(&sc).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_ne!(out.status.code(), Some(0), "{args:?} accepted");
        assert!(err.contains(&flag(args)) && err.contains(what), "{args:?}: {err}");
        assert!(!err.contains("panicked") && out.stdout.is_empty(), "{args:?}: {err}");
    }
    for args in [&["--levels", "2", "--max-memory", "-1G"][..], &["--levels", "2", "--steps", "0"]] {
        let out = bin().arg("adapt").arg(&sc).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(matches!(out.status.code(), Some(1 | 2)), "{args:?}: {err}");
        assert!(!err.contains("panicked") && err.lines().count() <= 3, "{args:?}: {err}");
    }
}

/// The system shall report a time indicator η_k (src/adapt/time.rs) that exceeds the space indicator
/// where the error is the time stepping's — mms_stop, slip stopping abruptly inside a step, whose true
/// error levels off at its O(k) time error while η falls — and stays below it where it is not: zero on
/// mms_elastic (no friction, loads affine in t: backward Euler is exact), below η on mms_stick_to_slip
/// (measured η_k/η ≤ 0.44 over these levels). η + η_k bounds the true error on mms_stop (the two bounds
/// add: total error ≤ space error + time error).
#[test]
fn time_indicator_exceeds_the_space_one_only_where_the_time_error_dominates() {
    let stop = rows(&scene("verification/cases/mms_stop.toml"), &options(10, 0.5, None));
    for r in &stop {
        println!(
            "mms_stop level {}: η {:.3e} η_k {:.3e} error {:.3e}",
            r.level,
            r.estimator,
            r.time_estimator,
            r.error.unwrap()
        );
        assert!(
            r.time_estimator > r.estimator,
            "mms_stop level {}: η_k {} ≤ η {}",
            r.level,
            r.time_estimator,
            r.estimator
        );
        assert!(r.estimator + r.time_estimator >= r.error.unwrap(), "level {}", r.level);
    }
    // the true error levels off (the time error) while η keeps falling: the case is time-dominated
    let (first, last) = (&stop[0], stop.last().unwrap());
    assert!(last.estimator < 0.5 * first.estimator && last.error.unwrap() > 0.5 * first.error.unwrap());
    for r in rows(&scene("verification/cases/mms_elastic.toml"), &options(8, 0.5, None)) {
        assert_eq!(r.time_estimator, 0.0, "mms_elastic level {}", r.level);
    }
    for r in rows(&scene("verification/cases/mms_stick_to_slip.toml"), &options(10, 0.5, None)) {
        println!("mms_stick_to_slip level {}: η {:.3e} η_k {:.3e}", r.level, r.estimator, r.time_estimator);
        assert!(r.time_estimator > 0.0 && r.time_estimator < r.estimator, "level {}", r.level);
    }
}

/// The system shall accumulate a dissipation mismatch D = Σ Δμⁿ·Δsⁿ whose every step is ≥ 0 (the
/// monotonicity of the friction law's subdifferential, src/adapt/time.rs), up to the friction solver's
/// tolerance on μ and s.
#[test]
fn dissipation_mismatch_is_non_negative_step_by_step() {
    let p = Problem::new(scene("verification/cases/mms_stick_to_slip.toml")).unwrap();
    let mut ti = tresca_cr::adapt::time::TimeIndicator::default();
    let (mut last, mut steps) = (0.0, 0);
    p.run(tresca_cr::RunOptions::all(), |r: &tresca_cr::StepResult| {
        ti.push(&p, r).unwrap();
        let scale: f64 = r.mu.iter().zip(&r.slip).map(|(m, s)| (m * s).abs()).sum();
        assert!(ti.dissipation - last >= -1e-10 * scale.max(1e-300), "step {}: {}", r.n, ti.dissipation - last);
        last = ti.dissipation;
        steps += 1;
        Ok(())
    })
    .unwrap();
    assert!(steps > 2 && ti.dissipation > 0.0, "the front moves: D = {}", ti.dissipation);
}

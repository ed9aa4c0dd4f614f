//! Stability at the extremes (issue 7): cheap library-level checks; the full study is
//! verification/stability.py (reference/stability.md).

use crate::common;
use common::*;
use tresca_cr::{Problem, Scene};

const EX51: &str = "verification/cases/paper_example_5_1.toml";
const NEAR: &str = "verification/cases/near_incompressible.toml";

fn text(path: &str) -> String {
    std::fs::read_to_string(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// Replace the first line starting with `key` (after trimming) by `line`.
fn with_line(text: &str, key: &str, line: &str) -> String {
    let mut done = false;
    let out: Vec<String> = text
        .lines()
        .map(|l| {
            if !done && l.trim_start().starts_with(key) {
                done = true;
                line.to_string()
            } else {
                l.to_string()
            }
        })
        .collect();
    assert!(done, "no line starting with {key}");
    out.join("\n")
}

fn scene_from(text: &str, refine: u32, steps: Option<usize>) -> Scene {
    let mut s = Scene::from_str(text, "stability-test").unwrap();
    s.set_refine(refine).unwrap();
    if let Some(n) = steps {
        s.set_steps(n).unwrap();
    }
    s
}

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

/// u ∝ 1/E exactly: the step problems for E and 1 map onto each other by v ↦ v/E (j_h is homogeneous).
#[test]
fn displacement_scales_exactly_as_one_over_e() {
    let base = text(EX51);
    let (_, r1) = run(scene_from(&with_line(&base, "E ", "E = 1.0"), 1, Some(20)));
    let scale = max_abs(&r1.last().unwrap().u);
    for e in [1e-3, 1e9] {
        let (_, re) = run(scene_from(&with_line(&base, "E ", &format!("E = {e:e}")), 1, Some(20)));
        for (a, b) in re.iter().zip(&r1) {
            let d = a.u.iter().zip(&b.u).map(|(x, y)| (e * x - y).abs()).fold(0.0, f64::max);
            assert!(d <= 1e-12 * scale, "E = {e:e}, step {}: {d:e}", a.n);
        }
    }
}

/// g_a = 0 is the frictionless limit (μ = 0); a huge g_a sticks everywhere without overflow.
#[test]
fn friction_bound_limits() {
    let base = text(EX51);
    let (_, free) = run(scene_from(&with_line(&base, "g_a", "g_a = \"0\""), 1, Some(20)));
    assert!(free.iter().all(|r| r.mu.iter().all(|&m| m == 0.0)));
    let (_, tiny) = run(scene_from(&with_line(&base, "g_a", "g_a = \"1e-12\""), 1, Some(20)));
    let d = rel_diff(&tiny.last().unwrap().u, &free.last().unwrap().u);
    assert!(d <= 1e-9, "g_a = 1e-12 vs 0: {d:e}");
    let (_, stuck) = run(scene_from(&with_line(&base, "g_a", "g_a = \"1e12\""), 1, Some(20)));
    for r in &stuck {
        assert!(r.u.iter().all(|v| v.is_finite()));
        assert_eq!(r.n_slip(), 0, "step {}", r.n);
        assert!(max_abs(&r.slip) <= 1e-12 * max_abs(&r.u).max(1e-300), "step {}", r.n);
    }
}

/// Tiny steps: K does not depend on k; while everything sticks, u(tₙ) is linear in tₙ.
#[test]
fn tiny_time_steps_are_harmless() {
    let base = text(EX51);
    let run_k = |k: f64| run(scene_from(&with_line(&base, "T ", &format!("T = {:e}", 4.0 * k)), 1, Some(4))).1;
    let (a, b) = (run_k(1e-6), run_k(1e-4));
    for (x, y) in a.iter().zip(&b).skip(1) {
        assert_eq!(x.n_slip(), 0);
        let xs: Vec<f64> = x.u.iter().map(|v| v / 1e-6).collect();
        let ys: Vec<f64> = y.u.iter().map(|v| v / 1e-4).collect();
        let d = rel_diff(&xs, &ys);
        assert!(d <= 1e-12, "step {}: {d:e}", x.n);
    }
}

/// Locking-free: on the divergence-free manufactured case the CR energy error does not grow as ν → ½.
#[test]
fn crouzeix_raviart_does_not_lock() {
    let base = text(NEAR);
    let err = |nu: f64| {
        let t =
            with_line(&with_line(&base, "E ", &format!("E  = {:?}", 2.0 * (1.0 + nu))), "nu ", &format!("nu = {nu:?}"));
        let (_, r) = run(scene_from(&t, 2, None));
        max_errors(&r).0
    };
    let (e03, e_inc) = (err(0.3), err(0.49999));
    println!("energy error nu = 0.3: {e03:.4e}, nu = 0.49999: {e_inc:.4e}");
    assert!(e_inc <= 1.5 * e03, "{e_inc:e} vs {e03:e}");
}

/// Never a non-finite result: extreme but legal settings give finite steps (or an error, never NaN).
#[test]
fn extreme_settings_give_finite_results() {
    let ex = text(EX51);
    for t in [
        with_line(&ex, "rho", "rho = 1e-12"),
        with_line(&ex, "rho", "rho = 1e8"),
        with_line(&with_line(&ex, "E ", "E = 1e-9"), "nu ", "nu = 0.4999999"),
    ] {
        let s = scene_from(&t, 1, Some(10));
        match Problem::new(s) {
            Err(e) => println!("refused: {e}"),
            Ok(p) => {
                let r = p.run(tresca_cr::RunOptions::all(), |r| {
                    assert!(r.u.iter().chain(&r.mu).chain(&r.slip).all(|v| v.is_finite()), "step {}", r.n);
                    Ok(())
                });
                if let Err(e) = r {
                    println!("stopped: {e}");
                }
            }
        }
    }
}

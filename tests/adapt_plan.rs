//! `tresca-cr plan` weighs the adaptive route against the uniform plan (src/plan/adaptive.rs) and says
//! which it recommends, in its output and in the --json summary.

use std::path::{Path, PathBuf};
use std::process::Command;

fn plan(case: &str, target: &str, extra: &[&str], name: &str) -> (Option<i32>, serde_json::Value, String) {
    let json: PathBuf = std::env::temp_dir().join(format!("tresca_adapt_plan_{}_{name}.json", std::process::id()));
    let sc = Path::new(env!("CARGO_MANIFEST_DIR")).join(case);
    let out = Command::new(env!("CARGO_BIN_EXE_tresca-cr"))
        .arg("plan")
        .arg(&sc)
        .args(["--target", target])
        .args(extra)
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(
        text.contains("recommended") || text.contains("not weighed"),
        "{text}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let _ = std::fs::remove_file(&json);
    (out.status.code(), v["plan"]["adaptive"].clone(), text)
}

fn f(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("{key} in {v}"))
}

/// The system shall, on Example 5.1 (corner singularities: the indicator decays like N^(−1/2) on adapted
/// meshes, N^(−0.43) on uniform ones, reference/adaptive.md), predict that the adaptive route needs
/// several times fewer unknowns for the target and recommend it where the uniform run does not fit the
/// memory given (5e-5 in 4 GB: uniform refine 9 or 10, 1.6 M or 6.3 M unknowns, 5.3 or 21 GB — the
/// uniform pilot's depth depends on its timings), with the plan's exit code 0 although no uniform
/// configuration fits. Rate: the pilot's law within 0.05 of the measured 0.5 (as in `tests/adapt.rs`). Unknowns: at rates 0.49 and 0.42 the ratio grows like target^(−0.34); the uniform
/// plan's whole refinements overshoot the target by up to 2^0.87, so the ratio at 5e-5 measured 3.8
/// (refine 9) and 9.4 (refine 10), at 1e-4 3.7–3.9: asked ≥ 3 and ≥ 2.
#[test]
fn example_5_1_plan_prefers_the_adaptive_route_where_uniform_does_not_fit() {
    let (code, a, _) = plan("verification/cases/paper_example_5_1.toml", "5e-5", &["--max-memory", "4G"], "a");
    assert_eq!(code, Some(0), "{a}");
    assert_eq!(a["choice"], "adaptive", "{a}");
    assert!((f(&a, "adaptive_rate") - 0.5).abs() <= 0.05, "{a}");
    assert!(f(&a, "uniform_unknowns") >= 3.0 * f(&a, "adaptive_unknowns"), "{a}");
    assert!(f(&a, "adaptive_memory") <= 4.0 * f64::from(1u32 << 30), "{a}");
    let (code, a, _) = plan("verification/cases/paper_example_5_1.toml", "1e-4", &[], "b");
    assert_eq!(code, Some(0));
    assert!(f(&a, "uniform_unknowns") >= 2.0 * f(&a, "adaptive_unknowns"), "{a}");
    assert!(a["adaptive_pilot"].as_array().unwrap().len() >= 8, "{a}");
}

/// The system shall pilot the adaptive route cheaply (issue 32: the planner's CPU ≤ 5 % of the plan),
/// counted, not timed: on Example 5.1 at 1e-4 the adaptive pilot runs on the space pilot's 5 steps (the time
/// pilot shows the steps do not change the answer; the scene has 40), is lean (no time indicator; the
/// distances between levels are computed for its error estimate) and stops at the first level with at least `PILOT_UNKNOWNS` (1/128) of the
/// uniform plan's unknowns; the route is priced at the plan's 40 steps.
#[test]
fn example_5_1_adaptive_pilots_are_lean_and_stop_at_a_share_of_the_uniform_plan() {
    let (code, a, _) = plan("verification/cases/paper_example_5_1.toml", "1e-4", &[], "d");
    assert_eq!(code, Some(0), "{a}");
    assert_eq!(a["pilot_steps"], 5, "{a}");
    assert_eq!(a["steps"], 40, "{a}");
    let until = f(&a, "uniform_unknowns") * tresca_cr::plan::adaptive::PILOT_UNKNOWNS;
    let rows = a["adaptive_pilot"].as_array().unwrap();
    let n: Vec<f64> = rows.iter().map(|r| r["unknowns"].as_f64().unwrap()).collect();
    assert!(n[n.len() - 1] >= until && n[n.len() - 2] < until, "{n:?} against {until}");
    assert!(rows.iter().all(|r| r["time_estimator"] == 0.0), "{rows:?}");
    assert!(rows[1..].iter().all(|r| r["estimate"].is_f64()), "{rows:?}");
    assert!(a["uniform_pilot"].as_array().unwrap().is_empty(), "{a}");
}

/// The system shall, on mms_elastic (a smooth solution: the uniform space order is CR's optimal 1), not
/// pilot the adaptive route — it can gain nothing but its overhead, and its pilots would add to the
/// planner's own cost (issue 32: ≤ 5 % of the plan) — and say so; the uniform plan stands alone.
#[test]
fn mms_elastic_plan_does_not_weigh_the_adaptive_route() {
    let (code, a, text) = plan("verification/cases/mms_elastic.toml", "1e-2", &[], "c");
    assert_eq!(code, Some(0), "{text}");
    assert!(a.is_null(), "{a}");
    assert!(text.contains("Adaptive route not weighed: the uniform space order"), "{text}");
}

/// The system shall, with `--run`, run the route it recommends: on `mms_lshape` at 6e-2 within 300 MB only
/// the adaptive route fits, so `plan --run` runs the `adapt` loop until its error estimate reaches 0.8 of
/// the target, says whether it did and gives the true error, which meets the target (the scene has
/// `[exact]`), and does not run the uniform plan's study; exit code 0. The study-sized
/// `plan_run_runs_the_recommended_adaptive_route_at_3e_2` does the same at 3e-2 (make verify, T1).
#[test]
fn plan_run_runs_the_recommended_adaptive_route() {
    plan_run_adaptive("6e-2", "300M", "run_adaptive");
}

/// The system shall, with `--run`, run the route it recommends on `mms_lshape` at 3e-2 within 1 GB, where
/// only the adaptive route fits (the uniform plan is refine 6, 910,412 unknowns, 3 GB), as above.
#[test]
#[ignore = "study-sized (an adaptive loop to 3e-2 on mms_lshape, ~20 s CPU): make verify runs it, requirement T1"]
fn plan_run_runs_the_recommended_adaptive_route_at_3e_2() {
    plan_run_adaptive("3e-2", "1G", "run_adaptive_3e_2");
}

/// `plan --run` on `mms_lshape` at `target` within `memory` runs the adaptive route and meets the target.
fn plan_run_adaptive(target: &str, memory: &str, name: &str) {
    let (code, adaptive, text) =
        plan("verification/cases/mms_lshape.toml", target, &["--max-memory", memory, "--run"], name);
    assert_eq!(code, Some(0), "{text}");
    assert_eq!(adaptive["choice"].as_str(), Some("adaptive"), "{adaptive}");
    assert!(text.contains("Running the adaptive route"), "{text}");
    assert!(!text.contains("Running the plan (levels"), "the uniform plan was run: {text}");
    let reached =
        text.lines().find(|l| l.starts_with("reached the error estimate ")).unwrap_or_else(|| panic!("{text}"));
    assert!(reached.ends_with(": met"), "{reached}");
    let truth = text.lines().find(|l| l.starts_with("true energy error")).unwrap_or_else(|| panic!("{text}"));
    assert!(truth.ends_with(": met"), "the route stops at 0.8 T of its estimate: {truth}");
}

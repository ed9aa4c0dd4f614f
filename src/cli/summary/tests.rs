//! The summary's round trip and the --json path check.

use super::study::{Estimates, LevelEstimate, LevelSpec, OutputEstimate, OutputLevel};
use super::*;

fn errors(x: f64) -> Errors {
    Errors { energy: x, h1: 2.0 * x, l2: 0.5 * x }
}

fn level() -> Level {
    Level {
        refine: 2,
        steps: 16,
        h: 0.125,
        k: 1.0 / 16.0,
        dofs: 1234,
        paper_dofs: 1200,
        wall: 0.01,
        setup: 0.004,
        iterations: 40,
        max_err: Some(errors(1e-2)),
        common_err: None,
        final_err: Some(errors(9e-3)),
        norm_max: 1.5,
        consecutive: Some([1e-3, 9e-4]),
        reference: None,
        estimate: Some(LevelEstimate { error_max: 1e-2, error_t: 9e-3, gci: 1.25e-2, verdict: "v".into() }),
        outputs: vec![0.25],
    }
}

/// The system shall write a summary that reads back to the same values (every part filled).
#[test]
fn summary_round_trips_through_json() {
    let mut s = Summary::new("run", "verification/cases/mms_front.toml", 1.5);
    let setup = Phases { space: 1e-3, assembly: 2e-3, factorisation: 3e-3, superposition: 4e-3, condensation: 5e-4 };
    s.check = Some(CheckSummary {
        vertices: 9,
        triangles: 8,
        edges: 16,
        h: 0.7,
        unknowns: 24,
        paper_dofs: 20,
        contact_unknowns: 4,
        steps: 3,
        solver: "ssn".into(),
        tol: 1e-12,
        max_iter: 100,
        exact: true,
        setup,
        memory: 1 << 20,
        disk: 4096,
        singular: Singular {
            points: vec![SingularPoint {
                x: 1.0,
                y: 1.0,
                angle: 1.5 * std::f64::consts::PI,
                parts: ["notch".into(), "ledge".into()],
                sides: ["free".into(), "free".into()],
                alpha: Some(0.5445),
                alpha_imag: Some(0.0),
                floor: false,
            }],
            uniform_order: 0.5445,
            adaptive_order: 0.5,
        },
    });
    let step = Step {
        n: 1,
        t: 0.5,
        iterations: 3,
        residual: 1e-13,
        stick: 2,
        slip: 1,
        errors: Some(errors(1e-3)),
        lengths: None,
    };
    s.run = Some(RunSummary {
        refine: 1,
        unknowns: 24,
        paper_dofs: 20,
        contact_edges: 3,
        steps: 2,
        solver: "ssn".into(),
        tol: 1e-12,
        setup,
        ordering: "AMD".into(),
        step_stats: vec![step.clone(), Step { errors: None, ..step }],
        iterations: 6,
        max_residual: 1e-13,
        max_errors: Some(errors(1e-3)),
        output: Some("out/run.h5".into()),
    });
    s.study = Some(StudySummary {
        levels: vec![level(), level()],
        reference: Some(LevelSpec { refine: 4, steps: 64 }),
        estimates: Estimates { size: "h".into(), p: Some(1.0), beta: Some(0.5), refused: None },
        output_names: vec!["max_slip".into()],
        outputs: vec![OutputEstimate {
            name: "max_slip".into(),
            p: None,
            limit: None,
            levels: vec![OutputLevel { estimate: 1e-3, gci: 1.25e-3, verdict: "v".into() }],
        }],
        difference_files: vec!["out/d/level_1.xdmf".into()],
    });
    s.plan = Some(super::plan::tests::plan(level()));
    let text = serde_json::to_string(&s).unwrap();
    let back: Summary = serde_json::from_str(&text).unwrap();
    assert_eq!(back, s);
    // the field names the verification scripts read
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    for key in ["schema", "command", "version", "commit", "scene", "status", "wall"] {
        assert!(v.get(key).is_some(), "{key}");
    }
    assert_eq!(v["run"]["setup"]["factorisation"], 3e-3);
    assert_eq!(v["run"]["step_stats"][0]["iterations"], 3);
}

/// The system shall refuse a --json path in a missing directory before doing any work.
#[test]
fn json_path_in_a_missing_directory_is_refused() {
    let e = check_path(Some(Path::new("no/such/dir/s.json"))).unwrap_err().to_string();
    assert!(e.contains("no/such/dir"), "{e}");
    assert!(check_path(Some(Path::new("s.json"))).is_ok());
    assert!(check_path(None).is_ok());
}

/// The system shall write an `adapt` summary that reads back to the same values, and read a summary
/// written before `adapt` existed (no `adapt` field) as one without it.
#[test]
fn adapt_summary_round_trips_and_old_summaries_still_read() {
    let row = tresca_cr::adapt::Row {
        level: 3,
        triangles: 120,
        unknowns: 340,
        paper_dofs: 320,
        contact_edges: 8,
        estimator: 2e-2,
        terms: [1e-6, 2e-4, 3e-6, 4e-8, 5e-5],
        worst_step: 4,
        error: None,
        vs_next: Some(4e-3),
        vs_reference: Some(5e-3),
        generation: 5,
        min_angle: 29.7,
        marked: 17,
        wall: 0.25,
        time_estimator: 3e-3,
        time_dissipation: 1e-3,
        time_load: 2e-3 / 3.0,
        richardson: Some(4.5e-3),
        estimate: Some(4.4e-3),
    };
    let opts = tresca_cr::adapt::Options { reference: Some(12), ..tresca_cr::adapt::Options::levels(4, 0.5) };
    let mut s = Summary::new("adapt", "verification/cases/lshape_adapt.toml", 2.0);
    s.adapt =
        Some(AdaptSummary::of(&opts, false, &[row.clone(), tresca_cr::adapt::Row { vs_reference: None, ..row }], None));
    let text = serde_json::to_string(&s).unwrap();
    let back: Summary = serde_json::from_str(&text).unwrap();
    assert_eq!(back, s);
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let l = &v["adapt"]["levels"];
    assert_eq!(l[0]["error"], 5e-3);
    assert_eq!(l[0]["error_kind"], "vs_reference");
    assert_eq!(l[1]["error_kind"], "vs_next");
    assert_eq!(l[0]["effectivity"], 2e-2 / 5e-3);
    assert_eq!(l[0]["terms"]["stress_jump"], 2e-4f64.sqrt());
    let mut old = v.clone();
    old.as_object_mut().unwrap().remove("adapt");
    let back: Summary = serde_json::from_value(old).unwrap();
    assert_eq!(back.adapt, None);
}

//! Fuzzing (proptest): the scene parser, expression parsing/evaluation and the Gmsh reader never panic
//! on arbitrary or mutated input — they return a value or a typed error. The number of cases is
//! TRESCA_FUZZ_CASES (default 500 per target; `make verify` runs more). Each target prints how many
//! inputs ran and how they ended. Inputs that once panicked, aborted or were misreported (issue 18: a
//! mesh whose areas underflow, slivers, steps beyond memory, loads whose energy overflows; issue 34:
//! arrays longer than the schema, collapsing time steps, NaN output points, unrepresentable E, ρ and
//! coordinates) are kept in
//! `tests/fuzz_corpus/` and replayed by `corpus_replays_without_panic`: each must end in an error.

use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use tresca_cr::scene::MeshSpec;
use tresca_cr::{Problem, Scene};

fn cases() -> u32 {
    std::env::var("TRESCA_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(500)
}

const BASE: &str = include_str!("../verification/cases/paper_example_5_1.toml");
const MSH: &str = include_str!("../verification/cases/lshape.msh");

/// Apply byte-level edits (replace, delete, insert) at positions given as fractions of the length.
fn mutate(base: &str, edits: &[(f64, u8, u8)]) -> String {
    let mut b = base.as_bytes().to_vec();
    for &(pos, op, byte) in edits {
        if b.is_empty() {
            break;
        }
        let i = ((pos * b.len() as f64) as usize).min(b.len() - 1);
        let c = b" \n\"=[],.-+*/^()0123456789eExyztabcdefghijklmnopqrs_$#"[byte as usize % 53];
        match op % 3 {
            0 => b[i] = c,
            1 => {
                b.remove(i);
            }
            _ => b.insert(i, c),
        }
    }
    String::from_utf8_lossy(&b).into_owned()
}

/// A scene small enough to set up and run in a fuzz loop.
fn small(s: &Scene) -> bool {
    let steps_ok = s.times.len() <= 50;
    match &s.mesh {
        MeshSpec::Structured { cells, refine, .. } => steps_ok && *refine <= 2 && cells[0] * cells[1] <= 400,
        MeshSpec::Gmsh { .. } => false,
    }
}

fn no_panic<T>(what: &str, input: &str, f: impl FnOnce() -> T) {
    if catch_unwind(AssertUnwindSafe(f)).is_err() {
        panic!("{what} panicked on input:\n{input}");
    }
}

/// Run `cases()` generated inputs through `check`, which classifies each outcome; print the counts.
fn fuzz<S: Strategy>(name: &str, strategy: S, check: impl Fn(S::Value) -> &'static str)
where
    S::Value: std::fmt::Debug,
{
    let mut runner = proptest::test_runner::TestRunner::new(ProptestConfig {
        cases: cases(),
        failure_persistence: None,
        ..ProptestConfig::default()
    });
    let counts = std::cell::RefCell::new(std::collections::BTreeMap::<&'static str, usize>::new());
    runner
        .run(&strategy, |v| {
            *counts.borrow_mut().entry(check(v)).or_default() += 1;
            Ok(())
        })
        .unwrap();
    let c = counts.borrow();
    println!("fuzz {name}: {} inputs, no panic; outcomes {:?}", c.values().sum::<usize>(), *c);
}

fn edits() -> impl Strategy<Value = Vec<(f64, u8, u8)>> {
    prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..6)
}

/// Mutated scene files are parsed, validated, set up and run without a panic (comment lines are
/// stripped first so that every edit reaches the parser).
#[test]
fn scene_parser_and_setup() {
    let base: String = BASE.lines().filter(|l| !l.trim_start().starts_with('#')).collect::<Vec<_>>().join("\n");
    fuzz("scene", edits(), |e| {
        let text = mutate(&base, &e);
        let mut outcome = "parse error";
        no_panic("scene", &text, || {
            if let Ok(s) = Scene::from_str(&text, "fuzz.toml") {
                outcome = "too large to run";
                if small(&s) {
                    outcome = match Problem::new(s) {
                        Ok(p) => match p.run(tresca_cr::RunOptions::all(), |_| Ok(())) {
                            Ok(()) => "ran",
                            Err(_) => "run error",
                        },
                        Err(_) => "set-up error",
                    };
                }
            }
        });
        outcome
    });
}

/// Well-formed random expressions (a small grammar) and random token soup.
fn expression_text() -> impl Strategy<Value = String> {
    let leaf = prop::sample::select(vec!["x", "y", "t", "0", "1", "2.5", "1e-3", "1e308", "PI", "E", ".5"])
        .prop_map(String::from);
    let tree = leaf.prop_recursive(5, 40, 3, |inner| {
        prop_oneof![
            (
                prop::sample::select(vec!["sin", "cos", "exp", "sqrt", "abs", "ln", "tanh", "signum", "floor"]),
                inner.clone()
            )
                .prop_map(|(f, a)| format!("{f}({a})")),
            (inner.clone(), prop::sample::select(vec!["+", "-", "*", "/", "^"]), inner.clone())
                .prop_map(|(a, o, b)| format!("({a}){o}({b})")),
            (prop::sample::select(vec!["min", "max", "atan2"]), inner.clone(), inner.clone())
                .prop_map(|(f, a, b)| format!("{f}({a}, {b})")),
            inner.clone().prop_map(|a| format!("-{a}")),
            (inner.clone(), inner).prop_map(|(a, b)| format!("{a}^{b}")),
        ]
    });
    const TOK: [&str; 32] = [
        "x", "y", "t", "1", "2.5", "1e-3", "+", "-", "*", "/", "^", "(", ")", ",", "sin(", "cos(", "exp(", "sqrt(",
        "abs(", "min(", "max(", "ln(", "PI", "E", "signum(", "tanh(", "atan2(", " ", "0", "1e308", "z", ".5",
    ];
    let soup = prop::collection::vec(0usize..32, 0..24).prop_map(|t| t.iter().map(|&i| TOK[i]).collect::<String>());
    prop_oneof![3 => tree, 1 => soup]
}

/// Random expressions are parsed and evaluated without a panic; values are finite or errors.
#[test]
fn expressions() {
    let strategy = (expression_text(), -10.0f64..10.0, -10.0f64..10.0, 0.0f64..2.0);
    fuzz("expression", strategy, |(text, x, y, t)| {
        let mut outcome = "parse error";
        no_panic("expression", &text, || {
            if let Ok(e) = tresca_cr::scene::expr::Expr::parse("fuzz", &text) {
                outcome = match e.eval(x, y, t) {
                    Ok(v) => {
                        assert!(v.is_finite());
                        "finite value"
                    }
                    Err(_) => "evaluation error",
                };
            }
        });
        outcome
    });
}

/// Mutated Gmsh files are read without a panic.
#[test]
fn gmsh_reader() {
    fuzz("msh", prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..8), |e| {
        let text = mutate(MSH, &e);
        let mut outcome = "parse error";
        no_panic("msh", &text, || {
            if let Ok(raw) = tresca_cr::mesh::parse_gmsh(&text, "fuzz.msh") {
                outcome = if tresca_cr::mesh::Mesh::build(raw).is_ok() { "valid mesh" } else { "mesh error" };
            }
        });
        outcome
    });
}

/// Every input of the corpus is replayed (read, set up, run) and must give an error, not a panic.
#[test]
fn corpus_replays_without_panic() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_corpus");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.display().to_string();
        no_panic("corpus", &name, || match path.extension().and_then(|e| e.to_str()) {
            Some("msh") => assert!(tresca_cr::mesh::parse_gmsh(&text, &name).is_err(), "{name} parsed"),
            Some("toml") => {
                let ran = Scene::from_str(&text, &name)
                    .and_then(Problem::new)
                    .and_then(|p| p.run(tresca_cr::RunOptions::all(), |_| Ok(())));
                assert!(ran.is_err(), "{name} accepted")
            }
            _ => {}
        });
        n += 1;
    }
    assert!(n >= 2, "the corpus is empty");
}

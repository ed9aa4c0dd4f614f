//! Fuzzing (proptest): the scene parser, expression parsing/evaluation and the Gmsh reader never panic
//! on arbitrary or mutated input — they return a value or a typed error. The number of cases is
//! TRESCA_FUZZ_CASES (default 500 per target; `make verify` runs more). Failing inputs are kept by
//! proptest in tests/fuzz.proptest-regressions (the regression corpus, committed).

use proptest::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use tresca_cr::scene::MeshSpec;
use tresca_cr::{Problem, Scene};

fn cases() -> u32 {
    std::env::var("TRESCA_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(500)
}

const BASE: &str = include_str!("../verification/cases/paper_example_5_1.toml");
const MSH: &str = include_str!("scenes/lshape.msh");

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

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    /// Mutated scene files are parsed, validated, set up and run without a panic.
    #[test]
    fn scene_parser_and_setup(edits in prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..6)) {
        let text = mutate(BASE, &edits);
        no_panic("scene", &text, || {
            if let Ok(s) = Scene::from_str(&text, "fuzz.toml") {
                if small(&s) {
                    if let Ok(p) = Problem::new(s) {
                        let _ = p.run(|_| Ok(()));
                    }
                }
            }
        });
    }

    /// Random token strings are parsed and evaluated without a panic; values are finite or errors.
    #[test]
    fn expressions(tokens in prop::collection::vec(0usize..32, 0..24), x in -10.0f64..10.0, y in -10.0f64..10.0, t in 0.0f64..2.0) {
        const TOK: [&str; 32] = ["x", "y", "t", "1", "2.5", "1e-3", "+", "-", "*", "/", "^", "(", ")", ",", "sin(", "cos(", "exp(",
            "sqrt(", "abs(", "min(", "max(", "ln(", "PI", "E", "signum(", "tanh(", "atan2(", " ", "0", "1e308", "z", ".5"];
        let text: String = tokens.iter().map(|&i| TOK[i]).collect();
        no_panic("expression", &text, || {
            if let Ok(e) = tresca_cr::expr::Expr::parse("fuzz", &text) {
                if let Ok(v) = e.eval(x, y, t) {
                    assert!(v.is_finite());
                }
            }
        });
    }

    /// Mutated Gmsh files are read without a panic.
    #[test]
    fn gmsh_reader(edits in prop::collection::vec((0.0f64..1.0, any::<u8>(), any::<u8>()), 1..8)) {
        let text = mutate(MSH, &edits);
        no_panic("msh", &text, || {
            if let Ok(raw) = tresca_cr::mesh::parse_gmsh(&text, "fuzz.msh") {
                let _ = tresca_cr::mesh::Mesh::build(raw);
            }
        });
    }
}

//! `check` lists the scene's singular exponents: every polygon corner and change of condition, with the
//! leading exponent of plane-strain elasticity there, in its messages and its `--json` summary.

mod common;
use common::{bin, root, spawn};

/// The summary's `check.singular` record of a scene.
fn singular(scene: &str, name: &str) -> serde_json::Value {
    let json = common::tmp_in("tresca-singular", name);
    let o = spawn(bin().args(["check", &root(scene), "--json", json.to_str().unwrap()])).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    v["check"]["singular"].clone()
}

/// The system shall find the L-shape's re-entrant corner (1, 1), traction free on both sides, with Williams'
/// exponent 0.5445 (published to four digits), and bound the uniform order by it.
#[test]
fn check_finds_the_re_entrant_corner() {
    let s = singular("verification/cases/mms_lshape.toml", "lshape.json");
    let points = s["points"].as_array().unwrap();
    let corner = points.iter().find(|p| p["x"] == 1.0 && p["y"] == 1.0).expect("the corner (1, 1)");
    assert!((corner["angle"].as_f64().unwrap() - 1.5 * std::f64::consts::PI).abs() < 1e-12);
    assert_eq!(corner["sides"], serde_json::json!(["free", "free"]));
    assert!((corner["alpha"].as_f64().unwrap() - 0.5445).abs() < 5e-5);
    assert_eq!(s["uniform_order"], corner["alpha"]);
    assert_eq!(s["adaptive_order"], 0.5);
}

/// The system shall take a contact side's conservative bound: a sticking contact meeting a traction-free
/// side at a right angle is the clamped–free pair (0.7112 at ν = 0.3, from the root of the determinant).
#[test]
fn a_contact_side_takes_its_worst_condition() {
    let s = singular("verification/cases/paper_example_5_1.toml", "ex51.json");
    let corner = s["points"].as_array().unwrap().iter().find(|p| p["x"] == 0.0 && p["y"] == 0.0).unwrap().clone();
    assert_eq!(corner["parts"], serde_json::json!(["bottom", "left"]));
    assert_eq!(corner["sides"], serde_json::json!(["clamped", "free"]));
    assert!(corner["alpha"].as_f64().unwrap() < 1.0);
}

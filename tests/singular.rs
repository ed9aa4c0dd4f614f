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

/// The system shall mark a point whose exponent gives an error floor rather than a rate (α ≤ 1/12: h^α
/// falls by less than 2× over the 12 refinements a scene allows): the Hertz cylinder's polygonised arc in
/// contact has vertices of 179.31° whose sides may both slip, α = π/ω − 1 = 0.0039 (the slip paradox),
/// and `check` says so; its free arc's vertices (free–free, no exponent below 1) and the L-shape's corner
/// are not floors.
#[test]
fn check_marks_a_slip_paradox_floor() {
    let s = singular("verification/cases/hertz_a05.toml", "hertz.json");
    let points = s["points"].as_array().unwrap();
    let floors: Vec<&serde_json::Value> = points.iter().filter(|p| p["floor"] == true).collect();
    assert!(!floors.is_empty());
    for p in &floors {
        let omega = p["angle"].as_f64().unwrap();
        assert_eq!(p["sides"], serde_json::json!(["sliding", "sliding"]));
        assert!(omega < std::f64::consts::PI, "{p}");
        let alpha = p["alpha"].as_f64().unwrap();
        assert!((alpha - (std::f64::consts::PI / omega - 1.0)).abs() < 1e-6 && alpha <= 1.0 / 12.0, "{p}");
    }
    assert!(points.iter().filter(|p| p["sides"] == serde_json::json!(["free", "free"])).all(|p| p["floor"] == false));
    let l = singular("verification/cases/mms_lshape.toml", "lshape-floor.json");
    assert!(l["points"].as_array().unwrap().iter().all(|p| p["floor"] == false));
    let text = spawn(bin().args(["check", &root("verification/cases/hertz_a05.toml")])).wait_with_output().unwrap();
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("polygonised curve: slip-paradox floor"), "{text}");
}

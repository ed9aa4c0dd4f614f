//! Boundary data (issue 30): dirichlet `u` and contact `gap` (`fem::lifting`).

use crate::common;
use common::*;
use tresca_cr::Scene;

/// A unit square, Dirichlet left/right/top with `u`, frictionless contact bottom with `gap`, for the
/// affine field u = (a + c x − d y, b + d x) with time-dependent a, b, c, d: constant stress with
/// σ_xy = μ(−d + d) = 0, so f = 0, Γ_C is traction free tangentially (g_a = 0 is consistent) and
/// u·n = −(b + d x) on y = 0 (n = (0, −1)).
fn affine(extra: &str, gap: &str) -> String {
    let u = r#"["0.01*t + 0.02*t*x - 0.005*t*y", "-0.003*t + 0.005*t*x"]"#;
    format!(
        r#"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [3, 3]
refine = 1
[material]
E = 10.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
u = {u}
[[boundary]]
name = "right"
kind = "dirichlet"
u = {u}
[[boundary]]
name = "top"
kind = "dirichlet"
u = {u}
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0"
gap = "{gap}"
[time]
T = 1.0
steps = 4
[exact]
u = {u}
grad = [["0.02*t", "-0.005*t"], ["0.005*t", "0"]]
{extra}
"#
    )
}

/// The system shall reproduce an affine displacement imposed through `u` and `gap` exactly (CR holds
/// affine fields and the lifting takes exact edge means): errors at the level of rounding.
#[test]
fn affine_data_are_reproduced_exactly() {
    let s = Scene::from_str(&affine("", "0.003*t - 0.005*t*x"), "affine").unwrap();
    assert!(s.has_boundary_data());
    let (p, steps) = run(s);
    for r in &steps {
        let e = r.errors.unwrap();
        // |u| ≤ 0.03: rounding of sums of O(100) terms of that size
        assert!(e.energy < 1e-12 && e.l2 < 1e-13, "step {}: {e:?}", r.n);
        // the displacement written is w + u_L: at every midpoint the affine field itself
        let mid = p.displacement(&r.u, r.t).unwrap();
        for (e, m) in mid.iter().enumerate() {
            let x = p.mesh.midpoint(e);
            let t = r.t;
            let ex = [0.01 * t + 0.02 * t * x[0] - 0.005 * t * x[1], -0.003 * t + 0.005 * t * x[0]];
            assert!((m[0] - ex[0]).abs() < 1e-14 && (m[1] - ex[1]).abs() < 1e-14, "edge {e}: {m:?} vs {ex:?}");
        }
        let a = r.audit.unwrap();
        assert!(a.balance_residual.abs() < 1e-15, "step {}: {a:?}", r.n);
    }
}

/// The system shall refuse data that do not fit together, naming the problem: a gap that contradicts
/// the Dirichlet data at the shared corners, and u₀ that contradicts u_D(t₀).
#[test]
fn inconsistent_data_are_refused() {
    let wrong_gap = Scene::from_str(&affine("", "0.004*t - 0.005*t*x"), "gap").unwrap();
    let e = tresca_cr::Problem::new(wrong_gap).err().expect("refused").to_string();
    assert!(e.contains("inconsistent boundary data") && e.contains("common vertex"), "{e}");
    let u0 = "[initial]\nu0 = [\"0.001\", \"0\"]";
    let wrong_u0 = Scene::from_str(&affine(u0, "0.003*t - 0.005*t*x"), "u0").unwrap();
    let e = tresca_cr::Problem::new(wrong_u0).err().expect("refused").to_string();
    assert!(e.contains("inconsistent boundary data") && e.contains("initial.u0"), "{e}");
}

/// The system shall accept `u` only on dirichlet parts and `gap` only on contact parts.
#[test]
fn data_keys_on_the_wrong_kind_are_refused() {
    let text = affine("", "0").replace("kind = \"contact\"\ng_a = \"0\"", "kind = \"neumann\"");
    let e = Scene::from_str(&text, "k").map(|_| ()).expect_err("refused").to_string();
    assert!(e.contains("only contact parts take"), "{e}");
    let text = affine("", "0").replace("name = \"left\"\nkind = \"dirichlet\"", "name = \"left\"\nkind = \"neumann\"");
    let e = Scene::from_str(&text, "k").map(|_| ()).expect_err("refused").to_string();
    assert!(e.contains("only dirichlet parts take"), "{e}");
}

/// The system shall run a scene whose data are given as zero exactly as the scene without them.
#[test]
fn zero_data_are_the_scene_without_them() {
    let base = scene("verification/cases/mms_front.toml");
    let with = base
        .text
        .replace("kind = \"dirichlet\"", "kind = \"dirichlet\"\nu = [\"0\", \"0\"]")
        .replace("kind = \"contact\"", "kind = \"contact\"\ngap = \"0\"");
    let zero = Scene::from_str(&with, "zero").unwrap();
    assert!(!zero.has_boundary_data());
    let (_, a) = run(base);
    let (_, b) = run(zero);
    for (x, y) in a.iter().zip(&b) {
        assert!(x.u.iter().zip(&y.u).all(|(p, q)| p.to_bits() == q.to_bits()), "step {}", x.n);
    }
}

/// [`affine`] with the sides `left` and `right` made traction-free Neumann parts: no vertex then joins
/// the contact part to a part with data, so only the t₀ comparisons are made.
fn no_shared_data(gap: &str) -> String {
    let mut text = affine("", gap);
    for side in ["left", "right"] {
        let from = format!("name = \"{side}\"\nkind = \"dirichlet\"\nu = ");
        let at = text.find(&from).expect("side") + from.len();
        let end = at + text[at..].find('\n').expect("line");
        text.replace_range(at - from.len()..end, &format!("name = \"{side}\"\nkind = \"neumann\""));
    }
    text
}

/// The system shall accept data that vanish at t₀ only up to rounding (the gap's terms cancel there:
/// (0.1 + t)² − 0.01 − 0.2t − t² = 1.7e-18 at t = 0, exactly 0 in exact arithmetic, while u₀ = 0 and
/// u_D(t₀) = 0 make the relative tolerance 0), and still refuse a mismatch of 1e-6 on the same data.
#[test]
fn rounding_of_data_that_vanish_at_t0_is_accepted() {
    let gap = "(0.1 + t)*(0.1 + t) - 0.01 - 0.2*t - t*t + 0.003*t - 0.005*t*x";
    let s = Scene::from_str(&no_shared_data(gap), "cancel").unwrap();
    if let Err(e) = tresca_cr::Problem::new(s) {
        panic!("refused: {e}");
    }
    let wrong = Scene::from_str(&no_shared_data(&format!("{gap} + 1e-6")), "off").unwrap();
    let e = tresca_cr::Problem::new(wrong).err().expect("refused").to_string();
    assert!(e.contains("inconsistent boundary data"), "{e}");
}

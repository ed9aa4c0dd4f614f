//! The compiled expressions against exmex's interpreter (what runs evaluated before compilation), on
//! every expression of `verification/cases/` at the quadrature points where runs evaluate them: the
//! degree-4 triangle rule on every element and the 2- and 3-point Gauss rules on every edge of the mesh
//! at refinement 2, at every time node of the scene.

use std::path::Path;
use tresca_cr::fem::quadrature::{edge_point, tri_point, GAUSS2, GAUSS3, TRI4};
use tresca_cr::mesh::Mesh;
use tresca_cr::scene::expr::{Expr, ExprSet};
use tresca_cr::scene::PartKind;
use tresca_cr::Scene;

/// Every expression string of a scene file (the keys that hold expressions).
fn expressions(v: &toml::Value, key: &str, out: &mut Vec<(String, String)>) {
    match v {
        toml::Value::String(s) if matches!(key, "g_a" | "traction" | "f" | "u0" | "u" | "grad") => {
            out.push((key.to_string(), s.clone()))
        }
        toml::Value::Array(a) => a.iter().for_each(|x| expressions(x, key, out)),
        toml::Value::Table(t) => t.iter().for_each(|(k, x)| expressions(x, k, out)),
        _ => {}
    }
}

#[test]
#[ignore = "study-sized (every case, every time node; ~50 s CPU): make verify runs it, requirement T1"]
fn compiled_agrees_with_interpreter_on_all_cases() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    let (mut worst, mut worst_at) = (0.0f64, String::new());
    let mut n_values = 0usize;
    for file in files.iter().filter(|p| p.extension().is_some_and(|e| e == "toml")) {
        let mut scene = Scene::from_file(file).unwrap();
        scene.set_refine(2).unwrap();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        let mut pts: Vec<[f64; 2]> = Vec::new();
        for t in &mesh.tris {
            let p = t.map(|v| mesh.points[v]);
            pts.extend(TRI4.iter().map(|(l, _)| tri_point(p, *l)));
        }
        for e in &mesh.edges {
            let [a, b] = e.map(|v| mesh.points[v]);
            pts.extend(GAUSS2.iter().chain(&GAUSS3).map(|(s, _)| edge_point(a, b, *s)));
        }
        let mut found = Vec::new();
        expressions(&toml::from_str::<toml::Value>(&scene.text).unwrap(), "", &mut found);
        assert!(!found.is_empty());
        for (key, text) in found {
            let e = Expr::parse(&key, &text).unwrap();
            let set = ExprSet::new(&[&e]);
            let bound = set.clone().bind(pts.clone());
            let reference = e.interpreted().unwrap();
            let (mut compiled, mut from_bound) = (Vec::new(), Vec::new());
            for &t in &scene.times {
                set.eval(&pts, t, &mut compiled).unwrap();
                // the spatial parts cached at binding: the same operations, so the same bits
                bound.eval(t, &mut from_bound).unwrap();
                assert!(compiled.iter().zip(&from_bound).all(|(a, b)| a.to_bits() == b.to_bits()), "{key} `{text}`");
                let exact: Vec<f64> = pts.iter().map(|p| reference.eval(p[0], p[1], t)).collect();
                // relative to the expression's size over the mesh at this time: these expressions are
                // sums of terms of that size, so a change of a few ulps in one term (integer powers as
                // products, shared subterms) shows as ~1e-16 of it, also where the sum cancels to ~0
                let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (i, (c, r)) in compiled.iter().zip(&exact).enumerate() {
                    let d = (c - r).abs() / scale.max(f64::MIN_POSITIVE);
                    n_values += 1;
                    if d > worst {
                        worst = d;
                        worst_at = format!("{} {key} `{text}` at {:?}, t={t}: {c} vs {r}", file.display(), pts[i]);
                    }
                }
            }
        }
    }
    println!("max relative difference compiled vs interpreted over {n_values} values: {worst:.3e} ({worst_at})");
    assert!(worst <= 1e-13, "max relative difference {worst:e}: {worst_at}");
}

/// The expressions compiled together as runs compile them (f, each traction, the exact u and ∇u), bound
/// to the degree-4 triangle points at refinement 2 (the spatial part cached, its choice made by the cost
/// model): every value has the bits of the expression compiled alone and evaluated without a cache.
#[test]
fn sets_as_runs_bind_them_match_single_expressions_bit_for_bit() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    let mut n_values = 0usize;
    for file in files.iter().filter(|p| p.extension().is_some_and(|e| e == "toml")) {
        let mut scene = Scene::from_file(file).unwrap();
        scene.set_refine(2).unwrap();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        let pts: Vec<[f64; 2]> =
            mesh.tris.iter().flat_map(|t| TRI4.map(|(l, _)| tri_point(t.map(|v| mesh.points[v]), l))).collect();
        let mut sets: Vec<Vec<&Expr>> = Vec::new();
        if let Some(f) = &scene.f {
            sets.push(f.0.iter().collect());
        }
        for part in &scene.parts {
            if let PartKind::Neumann(Some(g)) = &part.kind {
                sets.push(g.0.iter().collect());
            }
        }
        if let Some(x) = &scene.exact {
            sets.push(x.u.0.iter().chain(x.grad.iter().flatten()).collect());
        }
        for exprs in sets {
            let bound = ExprSet::new(&exprs).bind(pts.clone());
            let (mut together, mut alone) = (Vec::new(), Vec::new());
            for &t in &scene.times {
                bound.eval(t, &mut together).unwrap();
                for (k, e) in exprs.iter().enumerate() {
                    ExprSet::new(&[e]).eval(&pts, t, &mut alone).unwrap();
                    for (i, a) in alone.iter().enumerate() {
                        let b = together[i * exprs.len() + k];
                        assert_eq!(
                            a.to_bits(),
                            b.to_bits(),
                            "{} `{}` at {:?}, t={t}",
                            file.display(),
                            e.text(),
                            pts[i]
                        );
                        n_values += 1;
                    }
                }
            }
        }
    }
    println!("{n_values} values of sets bound to points: bit-identical to single expressions");
    assert!(n_values > 0);
}

/// The exact u and ∇u as the error norms evaluate them (`fem::exact::ExactAt`: separated in time where
/// they separate, else the bound program), at the degree-4 triangle points at refinement 2 and every time
/// node, against exmex's interpreter: within 1e-13 of each expression's size, the bound of the first test
/// (the separated route reassociates the same terms' products and sums).
#[test]
fn exact_solutions_as_the_error_norms_evaluate_them_agree_with_the_interpreter() {
    use tresca_cr::fem::exact::ExactAt;
    use tresca_cr::scene::expr::program::LANES;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    let (mut worst, mut worst_at, mut separated) = (0.0f64, String::new(), 0);
    for file in files.iter().filter(|p| p.extension().is_some_and(|e| e == "toml")) {
        let mut scene = Scene::from_file(file).unwrap();
        let Some(ex) = scene.exact.clone() else { continue };
        scene.set_refine(2).unwrap();
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        let pts: Vec<[f64; 2]> =
            mesh.tris.iter().flat_map(|t| TRI4.map(|(l, _)| tri_point(t.map(|v| mesh.points[v]), l))).collect();
        let (pe, n_el) = (TRI4.len(), mesh.tris.len());
        let at = ExactAt::new(&ex, pts.clone(), pe);
        separated += usize::from(at.is_separated());
        let exprs: Vec<&Expr> = ex.u.0.iter().chain(ex.grad.iter().flatten()).collect();
        let reference: Vec<_> = exprs.iter().map(|e| e.interpreted().unwrap()).collect();
        let (mut batch, mut values) = (Vec::new(), vec![0.0; pts.len() * 6]);
        for &t in &scene.times {
            // the batches of elements, back to point-major values
            for b in 0..n_el.div_ceil(LANES) {
                let n = LANES.min(n_el - b * LANES);
                at.eval_batch(&at.node(t), b, n, &mut batch).unwrap();
                for (e, q, k) in (0..n).flat_map(|e| (0..pe).flat_map(move |q| (0..6).map(move |k| (e, q, k)))) {
                    values[((b * LANES + e) * pe + q) * 6 + k] = batch[(k * pe + q) * LANES + e];
                }
            }
            for (k, r) in reference.iter().enumerate() {
                let exact: Vec<f64> = pts.iter().map(|p| r.eval(p[0], p[1], t)).collect();
                let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                for (i, e) in exact.iter().enumerate() {
                    let d = (values[i * 6 + k] - e).abs() / scale.max(f64::MIN_POSITIVE);
                    if d > worst {
                        worst = d;
                        worst_at = format!("{} `{}` at {:?}, t={t}", file.display(), exprs[k].text(), pts[i]);
                    }
                }
            }
        }
    }
    println!(
        "exact solutions ({separated} separated): max relative difference to the interpreter {worst:.3e} ({worst_at})"
    );
    assert!(separated > 0);
    assert!(worst <= 1e-13, "max relative difference {worst:e}: {worst_at}");
}

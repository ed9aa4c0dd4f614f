//! Requirement: a load that separates into time factors times space parts (`fem::loads`, assembled
//! once per factor) equals the load evaluated at every quadrature point of every node, to rounding:
//! on every scene of `verification/cases/` and the polynomial benchmark, at 33 times spanning the run
//! (kinks of the time factors included), the two routes differ by at most 1e-14 of the load's largest
//! entry (the parts are the same integrands with products and sums reassociated: a few ulps, summed
//! over at most 8 parts and 6 quadrature points per entry). Also: a time factor that is not finite at
//! a node is an error naming the expression and the time.

use std::path::Path;
use tresca_cr::fem::lifting::BoundaryData;
use tresca_cr::fem::loads::Loads;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::Mesh;
use tresca_cr::scene::expr::Vec2Expr;
use tresca_cr::Scene;

fn scene(rel: &str) -> Scene {
    Scene::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

#[test]
fn separated_loads_equal_the_pointwise_loads() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| format!("verification/cases/{}", p.file_name().unwrap().to_string_lossy()))
        .collect();
    files.sort();
    files.push("verification/bench/bench_mms_poly.toml".into());
    let mut separated = 0;
    for file in &files {
        let mut s = scene(file);
        if let tresca_cr::mesh::MeshSpec::Structured { cells, .. } = &mut s.mesh {
            // the benchmark's 256 × 128 cells are for timing; the integrands are the same on 16 × 8
            *cells = [cells[0].min(16), cells[1].min(16)];
        }
        let mesh = Mesh::from_spec(&s.mesh).unwrap();
        let space = CrSpace::new(&mesh, &s.parts).unwrap();
        let fast = Loads::new(&s, &mesh, &space, BoundaryData::of(&mesh, &s.parts, &space).as_ref()).unwrap();
        let slow = Loads::with_separation(&s, &mesh, &space, BoundaryData::of(&mesh, &s.parts, &space).as_ref(), false)
            .unwrap();
        separated += usize::from(fast.n_patterns() > 0);
        let (t0, t1) = (s.times[0], *s.times.last().unwrap());
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for k in 0..=32 {
            let t = t0 + (t1 - t0) * k as f64 / 32.0;
            fast.assemble_on_support(t, &mut a).unwrap();
            slow.assemble_on_support(t, &mut b).unwrap();
            let size = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = a.iter().zip(&b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(diff <= 1e-14 * size.max(f64::MIN_POSITIVE), "{file} at t = {t}: {diff:e} of {size:e}");
        }
    }
    // the manufactured stop/stick cases and the polynomial benchmark separate; the moving fronts do not
    assert!(separated >= 3, "only {separated} scenes separated");
}

#[test]
fn non_finite_time_factor_names_the_expression_and_time() {
    let mut s = scene("verification/cases/mms_stop.toml");
    let text = "x*y/(t - 0.5)";
    s.f = Some(Vec2Expr::parse("loads.f", &[text.into(), "0".into()]).unwrap());
    let mesh = Mesh::from_spec(&s.mesh).unwrap();
    let space = CrSpace::new(&mesh, &s.parts).unwrap();
    let loads = Loads::new(&s, &mesh, &space, BoundaryData::of(&mesh, &s.parts, &space).as_ref()).unwrap();
    assert!(loads.n_patterns() > 0);
    let mut l = Vec::new();
    loads.assemble_on_support(0.25, &mut l).unwrap();
    let e = loads.assemble_on_support(0.5, &mut l).unwrap_err().to_string();
    assert!(e.contains(text) && e.contains("t = 0.5"), "{e}");
}

/// Requirement: when the loads of the nodes span more than `MAX_RANK` patterns (mms_front's moving
/// front does not separate), the refused superposition hands over the loads it assembled on the way,
/// each equal to the load of its node, so the steps at those nodes reuse them instead of assembling
/// them again (`solve::free::FreeResponse`).
#[test]
fn a_refused_superposition_keeps_the_loads_it_assembled() {
    use tresca_cr::solve::superpose::{LoadBasis, MAX_RANK};
    let mut s = scene("verification/cases/mms_front.toml");
    s.set_refine(0).unwrap();
    s.set_steps(16).unwrap();
    let p = tresca_cr::Problem::new(s.clone()).unwrap();
    let loads = Loads::new(&s, &p.mesh, &p.space, p.data.as_ref()).unwrap();
    let mut kept = vec![(99, vec![1.0])];
    let basis = LoadBasis::build(&loads, &s.times, p.free.factor(), &mut kept).unwrap();
    assert!(basis.is_none(), "mms_front's loads were superposed");
    assert!(!kept.is_empty() && kept.len() <= MAX_RANK + 1, "{} loads kept", kept.len());
    let mut nodes: Vec<usize> = kept.iter().map(|(n, _)| *n).collect();
    nodes.sort();
    nodes.dedup();
    assert_eq!(nodes.len(), kept.len(), "a node kept twice");
    for (n, l) in &kept {
        let mut a = Vec::new();
        loads.assemble_on_support(s.times[*n], &mut a).unwrap();
        assert_eq!(&a, l, "node {n}");
    }
}

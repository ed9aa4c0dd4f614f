//! The true error norms evaluate the exact solution chunk of elements by chunk in parallel: a
//! non-finite exact value is still reported for the first quadrature point in order that has one, naming
//! the expression, whatever chunk finds it first; and the norms do not depend on the thread count.

use std::path::Path;
use tresca_cr::fem::elasticity::Elasticity;
use tresca_cr::fem::norms::ErrorEvaluator;
use tresca_cr::fem::quadrature::{tri_point, TRI4};
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::Mesh;
use tresca_cr::scene::expr::Expr;
use tresca_cr::Scene;

/// mms_stop at refinement `refine`: its scene, mesh, space and law.
fn mms_stop(refine: u32) -> (Scene, Mesh, CrSpace, Elasticity) {
    let mut scene =
        Scene::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases/mms_stop.toml")).unwrap();
    scene.set_refine(refine).unwrap();
    let mesh = Mesh::from_spec(&scene.mesh).unwrap();
    let space = CrSpace::new(&mesh, &scene.parts).unwrap();
    let law = Elasticity::new(&scene.material);
    (scene, mesh, space, law)
}

#[test]
fn non_finite_exact_value_names_expression_and_first_point() {
    let (scene, mesh, space, law) = mms_stop(4);
    let mut exact = scene.exact.clone().unwrap();
    // infinite where x >= 0.9: in many chunks of elements, none of them the first
    exact.grad[1][0] = Expr::parse("exact.grad[1][0]", "1/max(0.9-x, 0)").unwrap();
    let ev = ErrorEvaluator::new(&mesh, &space, scene.has_boundary_data(), &law, scene.rho).with_exact(&exact);
    let mid = vec![[0.0; 2]; mesh.edges.len()];
    let first = mesh
        .tris
        .iter()
        .flat_map(|t| TRI4.map(|(l, _)| tri_point(t.map(|v| mesh.points[v]), l)))
        .find(|p| p[0] >= 0.9)
        .unwrap();
    for _ in 0..3 {
        let e = ev.errors(&mesh, &exact, &mid, 0.5).unwrap_err().to_string();
        let at = format!("value inf at (x={}, y={}, t=0.5)", first[0], first[1]);
        assert!(e.contains("1/max(0.9-x, 0)") && e.contains(&at), "{e}\nexpected {at}");
    }
    // the exact solution itself: finite norms, the same bits every time
    let exact = scene.exact.clone().unwrap();
    let ev = ErrorEvaluator::new(&mesh, &space, scene.has_boundary_data(), &law, scene.rho).with_exact(&exact);
    let a = ev.errors(&mesh, &exact, &mid, 0.5).unwrap();
    let b = ErrorEvaluator::new(&mesh, &space, scene.has_boundary_data(), &law, scene.rho)
        .errors(&mesh, &exact, &mid, 0.5)
        .unwrap();
    assert!(a.energy.is_finite() && a.energy > 0.0);
    assert_eq!([a.energy, a.h1, a.l2].map(f64::to_bits), [b.energy, b.h1, b.l2].map(f64::to_bits));
}

/// Requirement (issue 13, error norms of several time nodes at once): `errors_at` gives the same norms,
/// bit for bit, as `errors` node by node, and where the exact solution is not finite at a later node it
/// returns the norms of the nodes before it and that node's error (a run hands out the steps before).
#[test]
fn error_norms_of_several_nodes_at_once_equal_node_by_node() {
    let (scene, mesh, space, law) = mms_stop(3);
    let exact = scene.exact.clone().unwrap();
    let ev = ErrorEvaluator::new(&mesh, &space, scene.has_boundary_data(), &law, scene.rho).with_exact(&exact);
    let mids: Vec<Vec<[f64; 2]>> = (0..3)
        .map(|k| (0..mesh.edges.len()).map(|e| [(e * (k + 1)) as f64 * 1e-5, 1e-3 * k as f64]).collect())
        .collect();
    let times = [0.1, 0.5, 0.9];
    let fields: Vec<(&[[f64; 2]], f64)> = mids.iter().zip(times).map(|(m, t)| (&m[..], t)).collect();
    let (norms, failed) = ev.errors_at(&mesh, &exact, &fields);
    assert!(failed.is_none());
    for (n, (m, t)) in norms.iter().zip(&fields) {
        assert_eq!(*n, ev.errors(&mesh, &exact, m, *t).unwrap());
    }
    // not finite from t = 0.7 on: the first two nodes' norms, then the error
    let mut late = exact.clone();
    late.u.0[0] = Expr::parse("exact.u[0]", "x/max(0.7-t, 0)").unwrap();
    let ev = ErrorEvaluator::new(&mesh, &space, scene.has_boundary_data(), &law, scene.rho).with_exact(&late);
    let (norms, failed) = ev.errors_at(&mesh, &late, &fields);
    assert_eq!(norms.len(), 2);
    assert!(failed.is_some_and(|e| e.to_string().contains("x/max(0.7-t, 0)")));
}

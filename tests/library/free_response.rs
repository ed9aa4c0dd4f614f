//! The free response u_f = K⁻¹lⁿ and its contact trace s_f = Eᵀu_f (`solve::free`) by each of its
//! routes — superposed load patterns, or the forward half-solve with the contact unknowns ordered last
//! (s_f = Wᵀy_c) followed by one backward half — against a direct solve of the assembled load with a
//! fresh factor of K.

use crate::common;
use common::*;
use tresca_cr::solve::cholesky::Factor;
use tresca_cr::solve::free::Free;
use tresca_cr::Problem;

/// Relative max-norm difference ≤ 1e-12: the routes differ only by the order of floating-point sums
/// over ≤ 4 load patterns (superposition) or over the unknowns (Zᵀl), a few ulps of the largest term
/// times the condition of K (≤ 1e4 on these meshes).
const TOL: f64 = 1e-12;

fn check(p: &Problem, label: &str) {
    let factor = Factor::new(&p.stiffness).unwrap();
    let dofs: Vec<usize> = p.space.contact.iter().map(|c| c.dof).collect();
    let mut load = Vec::new();
    for (n, &t) in p.scene.times.iter().enumerate().skip(1) {
        let mut direct = Vec::new();
        p.free.loads().assemble(t, &mut direct).unwrap();
        factor.solve_in_place(&mut direct);
        let trace: Vec<f64> = dofs.iter().map(|&k| direct[k]).collect();
        // u_f = uⁿ for μ = 0
        let free = p.free.at(n, t, true, &mut load).unwrap();
        let t_full = free.trace.clone();
        let u = p.free.with_friction(free, &vec![0.0; dofs.len()]).unwrap();
        assert!(rel_diff(&u, &direct) <= TOL, "{label} step {n}: u_f {:e}", rel_diff(&u, &direct));
        assert!(rel_diff(&t_full, &trace) <= TOL, "{label} step {n}: trace with u");
        let Free { u, trace: t_only, .. } = p.free.at(n, t, false, &mut load).unwrap();
        assert!(u.is_empty() || dofs.is_empty(), "{label}: u formed although not wanted");
        assert!(rel_diff(&t_only, &trace) <= TOL, "{label} step {n}: trace alone {:e}", rel_diff(&t_only, &trace));
    }
}

/// Proportional loads (Example 5.1: g = t g₁) take the superposition route; a load with sin(3ty) spans
/// more than 4 patterns and takes the assembly route (the Z shortcut for the trace alone); both agree
/// with the direct solve at every time node, and u_f − K⁻¹Eμ equals a direct solve of K u = l − Eμ.
#[test]
fn free_response_matches_a_direct_solve_on_every_route() {
    let s = scene("verification/cases/paper_example_5_1.toml");
    let p = Problem::new(s.clone()).unwrap();
    assert!(p.free.superposed());
    check(&p, "superposed");
    let mut text = s.text.replace("0.02*(5-y)*t", "0.02*(5-y)*sin(3*t*y)");
    text = text.replace("\"-0.01*t\"", "\"-0.01*t*cos(t*y)\"");
    assert_ne!(text, s.text, "the scene's traction changed: update this test");
    let q = Problem::new(tresca_cr::Scene::from_str(&text, "nonproportional.toml").unwrap()).unwrap();
    assert!(!q.free.superposed());
    check(&q, "assembled");
    // friction correction
    let mu: Vec<f64> = (0..q.space.contact.len()).map(|e| 1e-3 * (e as f64 + 1.0).sin()).collect();
    let mut load = Vec::new();
    let free = q.free.at(3, q.scene.times[3], true, &mut load).unwrap();
    let u = q.free.with_friction(free, &mu).unwrap();
    for (c, m) in q.space.contact.iter().zip(&mu) {
        load[c.dof] -= m;
    }
    let factor = Factor::new(&q.stiffness).unwrap();
    factor.solve_in_place(&mut load);
    assert!(rel_diff(&u, &load) <= TOL, "u_f − K⁻¹Eμ: {:e}", rel_diff(&u, &load));
}

/// Separated loads (`fem::loads`) are superposed from their patterns, without forming a load at a node:
/// mms_stop's four time factors (1 + t, 1 + t/2, and two kinks at t* = 1/3) give rank 4; the polynomial
/// benchmark's factors 1, t, …, t⁴ and 1 + t/2 span more than 4 and its steps assemble their loads.
#[test]
fn separated_loads_are_superposed_from_their_patterns() {
    let p = Problem::new(scene("verification/cases/mms_stop.toml")).unwrap();
    assert!(p.free.loads().separated().is_some_and(|v| v.len() == 4));
    assert!(p.free.superposed());
    check(&p, "patterns");
    let mut s = scene("verification/bench/bench_mms_poly.toml");
    if let tresca_cr::mesh::MeshSpec::Structured { cells, .. } = &mut s.mesh {
        *cells = [8, 4];
    }
    s.set_steps(8).unwrap();
    let q = Problem::new(s).unwrap();
    assert!(q.free.loads().separated().is_some() && !q.free.superposed());
    check(&q, "patterns beyond the rank");
}

//! The energy audit (`stepping::audit`): every step's balance a_h(uⁿ,δuⁿ) + j_h(δuⁿ) = (lⁿ,δuⁿ) + W_Γ holds
//! to the friction solver's tolerance and rounding on every contact scene, and a wrong friction sign
//! breaks it.

use crate::common;
use common::*;
use tresca_cr::{Problem, Scene, StepResult};

/// Every scene of verification/cases with a contact part, at its own mesh level.
fn contact_scenes() -> Vec<(String, Scene)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("verification/cases");
    let mut paths: Vec<_> = std::fs::read_dir(dir).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).collect();
    paths.sort();
    paths
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .map(|p| (p.display().to_string(), Scene::from_file(&p).unwrap()))
        .filter(|(_, s)| s.has_contact())
        .collect()
}

/// ‖v‖₂ of midpoint values.
fn norm(v: &[[f64; 2]]) -> f64 {
    v.iter().map(|x| x[0] * x[0] + x[1] * x[1]).sum::<f64>().sqrt()
}

/// The bound the balance residual of step `r` (after `prev`) must meet:
///
/// * friction: with natural residual r(μ) ≤ tol (relative to F ≤ max_e w_e), on each edge either μ_e is
///   inside the box and |Δs_e| ≤ C_ee·tol·F, so |μ_eΔs_e − w_e|Δs_e|| ≤ 2w_eC_ee·tol·F, or μ_e = ±w_e
///   (projected exactly) and the defect is ≤ |μ_e − P(…)|·|Δs_e| ≤ tol·F·|Δs_e|: in all
///   tol·F·Σ_e max(2w_eC_ee, |Δs_e|);
/// * rounding: the direct solve's backward error (K ŵ = b + δb, ‖δb‖ ≤ c·ε·‖K‖‖ŵ‖ with c of the order
///   of the nonzeros of a column of L, a few hundred here) and the sums of the matrix-free forms
///   (the same size), dotted with δU: c·ε·‖K‖_∞·‖U‖₂·‖δU‖₂, taken with c = 1000.
fn bound(p: &Problem, prev: &StepResult, r: &StepResult) -> f64 {
    let mut b = 0.0;
    if let Some(f) = &p.friction {
        let c = f.diagonal();
        let w: Vec<f64> = p.space.contact.iter().map(|e| e.length * e.g_mean).collect();
        let fmax = w.iter().fold(0.0f64, |a, v| a.max(*v));
        let sum: f64 = (0..w.len()).map(|e| (2.0 * w[e] * c[e]).max((r.slip[e] - prev.slip[e]).abs())).sum();
        b += p.scene.solver.tol * fmax * sum;
    }
    let k = &p.stiffness;
    let mut row = vec![0.0f64; k.nrows()];
    for j in 0..k.ncols() {
        // K's lower triangle: an entry below the diagonal counts in its row and, mirrored, in row j
        for (i, v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            row[i] += v.abs();
            if i != j {
                row[j] += v.abs();
            }
        }
    }
    let knorm = row.iter().fold(0.0f64, |a, v| a.max(*v));
    let (u, u0) = (p.displacement(&r.u, r.t).unwrap(), p.displacement(&prev.u, prev.t).unwrap());
    let du: Vec<[f64; 2]> = u.iter().zip(&u0).map(|(a, b)| [a[0] - b[0], a[1] - b[1]]).collect();
    b + 1000.0 * f64::EPSILON * knorm * norm(&u) * norm(&du)
}

/// The system shall balance the energy of every step of every contact scene: |balance residual| within
/// the bound of the friction tolerance and rounding, and the stored energy's increment equal to
/// a_h(uⁿ,δuⁿ) − ½a_h(δuⁿ,δuⁿ) (so the residual also equals ΔE + D + j − W_ext − W_Γ).
#[test]
fn every_contact_scene_balances_its_energy() {
    let scenes = contact_scenes();
    assert!(scenes.len() >= 8, "expected the repository's contact scenes, found {}", scenes.len());
    for (name, s) in scenes {
        let (p, steps) = run(s);
        let mut worst: f64 = 0.0;
        for w in steps.windows(2) {
            let (prev, r) = (&w[0], &w[1]);
            let a = r.audit.expect("every step of a run is audited");
            let b = bound(&p, prev, r);
            assert!(
                a.balance_residual.abs() <= b,
                "{name} step {}: residual {:e} > bound {b:e}",
                r.n,
                a.balance_residual
            );
            let e0 = prev.audit.unwrap().stored_energy;
            let identity =
                a.stored_energy - e0 + a.euler_dissipation + a.friction_dissipation - a.external_work - a.boundary_work;
            // the same sums regrouped: rounding of the largest term
            let scale = [a.stored_energy, e0, a.external_work, a.boundary_work, a.friction_dissipation]
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()));
            assert!((identity - a.balance_residual).abs() <= 1e-12 * scale, "{name} step {}: identity", r.n);
            worst = worst.max(a.balance_residual.abs() / b.max(f64::MIN_POSITIVE));
        }
        println!("{name}: max |residual| / bound = {worst:.2e}");
    }
}

/// The system's audit shall fail a step whose friction force has the wrong sign: uⁿ = K⁻¹(lⁿ + Eμ)
/// instead of K⁻¹(lⁿ − Eμ) gives a residual of about 2 j_h(δuⁿ), far beyond the bound.
#[test]
fn a_wrong_friction_sign_fails_the_audit() {
    for case in ["verification/cases/mms_front.toml", "verification/cases/mms_data_front.toml"] {
        let (p, steps) = run(scene(case));
        let mut failed = 0;
        for w in steps.windows(2).skip(1) {
            let (prev, good) = (&w[0], &w[1]);
            if good.audit.unwrap().friction_dissipation <= 0.0 {
                continue;
            }
            let mut load = Vec::new();
            let free = p.free.at(good.n, good.t, true, &mut load).unwrap();
            let flipped: Vec<f64> = good.mu.iter().map(|m| -m).collect();
            let u = p.free.with_friction(free, &flipped).unwrap();
            let mut bad = good.clone();
            bad.slip = p.space.contact.iter().map(|c| u[c.dof]).collect();
            bad.u = u;
            let state = p.audit_state(prev).unwrap();
            let (bad, _) = p.audited(state.as_ref(), &bad).unwrap();
            let a = bad.audit.unwrap();
            let b = bound(&p, prev, &bad);
            assert!(a.balance_residual.abs() > 100.0 * b, "{case} step {}: {:e} vs {b:e}", bad.n, a.balance_residual);
            failed += 1;
        }
        assert!(failed > 10, "{case}: only {failed} slipping steps checked");
    }
}

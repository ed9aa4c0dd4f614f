//! The box-QP solvers on small problems whose KKT solution is known: every edge sticking, slipping
//! either way, a mix, a frictionless edge, and a case on which plain PDAS cycles. The oracle is an
//! exhaustive search over the 3ⁿ sign patterns (stick, +slip, −slip) of Tresca's law, independent of
//! the solvers: on a stick set S and slip signs σ, μ_slip = σw and C_SS μ_S = d_S − C_{S,slip} μ_slip;
//! the pattern is the solution iff |μ_S| ≤ w_S and σ_e Δs_e ≥ 0 on the slip set.

use super::*;

/// The KKT solution by enumeration (unique: C is SPD, so the QP is strictly convex).
fn oracle(c: &DMatrix<f64>, d: &[f64], w: &[f64]) -> Vec<f64> {
    let n = d.len();
    for code in 0..3usize.pow(n as u32) {
        let sign: Vec<i32> = (0..n).map(|e| (code / 3usize.pow(e as u32) % 3) as i32 - 1).collect();
        let stick: Vec<usize> = (0..n).filter(|&e| sign[e] == 0).collect();
        let mut mu: Vec<f64> = (0..n).map(|e| f64::from(sign[e]) * w[e]).collect();
        if !stick.is_empty() {
            let css = DMatrix::from_fn(stick.len(), stick.len(), |i, j| c[(stick[i], stick[j])]);
            let rhs = nalgebra::DVector::from_iterator(
                stick.len(),
                stick.iter().map(|&i| d[i] - (0..n).filter(|&j| sign[j] != 0).map(|j| c[(i, j)] * mu[j]).sum::<f64>()),
            );
            let x = css.lu().solve(&rhs).expect("C_SS is SPD");
            for (k, &e) in stick.iter().enumerate() {
                mu[e] = x[k];
            }
        }
        let ds: Vec<f64> = (0..n).map(|i| d[i] - (0..n).map(|j| c[(i, j)] * mu[j]).sum::<f64>()).collect();
        let ok = (0..n).all(|e| match sign[e] {
            0 => mu[e].abs() <= w[e] * (1.0 + 1e-12),
            s => f64::from(s) * ds[e] >= -1e-12,
        });
        if ok {
            return mu;
        }
    }
    panic!("no sign pattern satisfies Tresca's law: the oracle is wrong")
}

fn mat(rows: &[&[f64]]) -> DMatrix<f64> {
    DMatrix::from_fn(rows.len(), rows.len(), |i, j| rows[i][j])
}

/// A friction problem (C, d, w) and what it exercises.
type Case = (&'static str, DMatrix<f64>, Vec<f64>, Vec<f64>);

/// Friction problems (C, d, w) and what each exercises.
fn cases() -> Vec<Case> {
    let c2 = mat(&[&[2.0, 0.5], &[0.5, 1.0]]);
    vec![
        ("all stick", c2.clone(), vec![0.5, 0.3], vec![1.0, 1.0]),
        ("all slip +", c2.clone(), vec![10.0, 10.0], vec![1.0, 1.0]),
        ("all slip -", c2.clone(), vec![-10.0, -10.0], vec![1.0, 1.0]),
        ("slip + and stick", c2.clone(), vec![5.0, 0.7], vec![1.0, 1.0]),
        ("slip - and slip +", c2.clone(), vec![-6.0, 4.0], vec![0.5, 2.0]),
        ("frictionless edge", c2, vec![3.0, 0.2], vec![0.0, 1.0]),
        (
            "pdas cycles",
            mat(&[&[12.0, 10.0, -11.0], &[10.0, 15.0, -13.0], &[-11.0, -13.0, 14.0]]),
            vec![7.0, 6.0, 5.0],
            vec![1.0, 1.0, 1.0],
        ),
    ]
}

/// Warm start used for the PDAS cycling witness (found by random search: from μ₀ = 0 it converges).
const CYCLE_START: [f64; 3] = [-1.0, -1.0, 1.0];

fn settings(method: Method) -> SolverSettings {
    SolverSettings { method, tol: 1e-12, max_iter_given: None, uzawa_step: 0.0 }
}

/// Every solver reaches the oracle's μ on every case (PDAS: except where it cycles, which it must report),
/// with the stick/slip classification the oracle's Δs implies. Tolerance: the solvers stop at natural
/// residual 1e-12 relative to the force scale (≈ 1 here); with cond(C) ≤ ~10³ μ is then within ~1e-9.
#[test]
fn solvers_reach_the_kkt_solution() {
    for method in [Method::Ssn, Method::Pdas, Method::Uzawa] {
        for (name, c, d, w) in cases() {
            let want = oracle(&c, &d, &w);
            let fr = Friction::from_parts(c.clone(), w.clone(), w.clone(), settings(method));
            let mu0 = if name == "pdas cycles" { CYCLE_START.to_vec() } else { vec![0.0; d.len()] };
            let got = fr.solve(&d, &mu0, 7, 0.5);
            if method == Method::Pdas && name == "pdas cycles" {
                let e = got.expect_err("plain PDAS cycles on this case").to_string();
                assert!(e.contains("cycling") && e.contains("step 7"), "{e}");
                continue;
            }
            let sol = got.unwrap_or_else(|e| panic!("{method:?} on {name}: {e}"));
            let err = sol.mu.iter().zip(&want).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(err <= 1e-9, "{method:?} on {name}: μ {:?}, oracle {want:?}", sol.mu);
            let lo: Vec<f64> = w.iter().map(|w| -w).collect();
            let qp = Qp { c: &c, d: &d, lo: &lo, hi: &w };
            let ds = qp.slip_increment(&want);
            for (e, dse) in ds.iter().enumerate() {
                let slips = dse.abs() > 1e-9;
                assert_eq!(sol.state[e] == EdgeState::Slip, slips, "{method:?} on {name}, edge {e}");
            }
        }
    }
}

/// A solver that runs out of iterations is reported with the step and time of the failing step.
#[test]
fn non_convergence_names_step_and_time() {
    let (_, c, d, w) = cases().pop().expect("cases");
    let mut s = settings(Method::Uzawa);
    s.max_iter_given = Some(2);
    let fr = Friction::from_parts(c, w.clone(), w, s);
    let e = fr.solve(&d, &[0.0; 3], 12, 0.375).expect_err("2 Uzawa iterations cannot reach 1e-12");
    match e {
        Error::NotConverged { step, time, solver, iterations, .. } => {
            assert_eq!((step, time, solver, iterations), (12, 0.375, "uzawa", 2));
        }
        other => panic!("unexpected error {other}"),
    }
}

/// A unilateral Tresca problem on a chain of `nc` edges at x_e = (e + ½)/nc: C the Laplace kernel
/// exp(−|x − x'|/0.2) over the tangential and normal unknowns (the normal ones at x_e + 0.003) plus 0.05 I
/// (SPD), w_e = 0.05 (1 + x_e), normal forces in [0, ∞), d = (sin 3x + a, cos 4x + a): several stick/slip
/// and contact/separation fronts along the chain.
fn chain_problem(nc: usize, a: f64) -> (DMatrix<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
    let x = |k: usize| (((k % nc) as f64 + 0.5) / nc as f64, if k < nc { 0.0 } else { 0.003 });
    let c = DMatrix::from_fn(2 * nc, 2 * nc, |i, j| {
        let ((xi, si), (xj, sj)) = (x(i), x(j));
        (-((xi + si) - (xj + sj)).abs() / 0.2).exp() + if i == j { 0.05 } else { 0.0 }
    });
    let d = (0..2 * nc).map(|k| if k < nc { (3.0 * x(k).0).sin() + a } else { (4.0 * x(k).0).cos() + a }).collect();
    let w: Vec<f64> = (0..nc).map(|e| 0.05 * (1.0 + x(e).0)).collect();
    let lo = w.iter().map(|w| -w).chain(std::iter::repeat_n(0.0, nc)).collect();
    let hi = w.iter().copied().chain(std::iter::repeat_n(f64::INFINITY, nc)).collect();
    (c, d, lo, hi)
}

/// The system shall solve the QP with normal unknowns by the active-set method of `hik`, from λ = 0 (the
/// nested predictor's sets, 40 edges: levels of 20, 10 and 5 groups) and from the solution of another load
/// (a warm start), to the λ of the projected Newton method of `ssn` (a different method: the QP is strictly
/// convex, its solution unique). Tolerance: both stop at natural residual 1e-12 relative to the force scale
/// (≈ 1); cond(C) ≤ ~10³ leaves λ within ~1e-9.
#[test]
fn active_set_method_reaches_the_projected_newton_solution() {
    let nc = 40;
    let levels = nested::Levels::of_chains(&vec![0; nc], &(0..nc).collect::<Vec<_>>(), vec![1.0 / nc as f64; nc]);
    assert_eq!(levels.len(), 3);
    let (c, d0, lo, hi) = chain_problem(nc, 0.0);
    let qp0 = Qp { c: &c, d: &d0, lo: &lo, hi: &hi };
    let warm = hik::solve(&qp0, &vec![0.0; 2 * nc], 1e-12, 200, &levels).expect("hik from 0").0;
    for a in [0.0, 0.3, -0.2] {
        let (_, d, _, _) = chain_problem(nc, a);
        let qp = Qp { c: &c, d: &d, lo: &lo, hi: &hi };
        let want = ssn::solve(&qp, &vec![0.0; 2 * nc], 1e-12, 500).expect("ssn").0;
        for start in [vec![0.0; 2 * nc], warm.clone()] {
            let (got, _, res) = hik::solve(&qp, &start, 1e-12, 200, &levels).expect("hik");
            assert!(res <= 1e-12);
            let err = got.iter().zip(&want).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(err <= 1e-9, "a = {a}: |λ_hik − λ_ssn| = {err:e}");
        }
    }
}

//! Coulomb friction on the condensed problem with normal unknowns (`normal`): the semismooth Newton
//! method of Hüeber, Stadler & Wohlmuth (SIAM J. Sci. Comput. 30(2), 2008) in its primal–dual
//! active-set form. With c_e = 1/C_ee (per unknown) and Δ = d − Cλ, the conditions of every edge are the
//! nonlinear complementarity functions
//!   normal (unilateral):  P_e − max(0, P_e + c Δ_n,e) = 0,
//!   tangential:           max(θ_e, |y_e|) μ_e − θ_e y_e = 0,   y_e = μ_e + c Δs_e,
//! with the threshold θ_e = F̄_e max(0, P_e + c Δ_n,e) inside the max (F̄_e |P_e + c Δ_n,e| on a bilateral
//! edge; Tresca's w_e on a Tresca edge of the same scene). A Newton step on them is the linear solve on
//! the active sets they give: a separated edge has P_e = 0 and μ_e = 0 (Coulomb) or |μ_e| ≤ w_e (Tresca),
//! a closed edge Δ_n,e = 0; a sticking edge Δs_e = 0, a slipping one μ_e = σ_e F̄_e P_e (σ_e = sign y_e;
//! in 2D the tangent is a line and this linearisation is exact). Iterated until the natural residual
//! (`Qp::residual` with the bounds of the current P) is ≤ tol; a repeated active set (the iteration
//! cycles, as for a large F̄) or the iteration limit stops it, reported as non-convergence.
//!
//! The start. λ₀ is the previous step's solution, as HSW start each load step; the first iteration takes
//! the active sets of λ₀ itself, read from its forces (`warm_sets`: separated where a unilateral P₀ is 0,
//! slip where μ₀ is at its threshold, stick elsewhere), not those of λ₀'s residual against the new load.
//! That residual counts the whole increment of the step as predicted slip and penetration, which inflates
//! the threshold F̄(P + cΔ_n) and moves the sets far from the solution's; the iteration then walks the
//! stick/slip boundary back a few edges per iteration, a number that grows with 1/h. From the previous
//! sets, a step whose sets did not change is solved by one Newton step (checked at the next iteration),
//! at every h. Where they changed, and at the first step (λ₀ = 0), the iteration goes on from the sets
//! of the nested iteration (`nested`: the same problem on groups of 2, 4, … Γ_C edges, coarse to fine),
//! whose fronts are within a couple of edges of the solution's at every h; from λ₀'s sets alone it walks
//! a moved stick/slip boundary about one edge per iteration. Where the iteration from the predicted sets
//! stops short (it is not globalised), the plain iteration from λ₀ runs, with the iterations spent.

use super::nested::{Levels, COARSE_ITER};
use super::{stalled, Qp, Solved};
use nalgebra::{DMatrix, DVector};
use std::collections::HashSet;

/// The coefficients of the edges: F̄_e of a Coulomb edge (`None`: Tresca's bound w_e).
pub type Coefficients<'a> = &'a [Option<f64>];

/// The friction threshold of edge e for the normal force `p`: w_e (Tresca) or F̄_e |p| (Coulomb).
pub fn threshold(f: Coefficients, w: &[f64], e: usize, p: f64) -> f64 {
    match f[e] {
        Some(f) => f * p.abs(),
        None => w[e],
    }
}

/// Solve from λ₀ = (μ₀, P₀); `w` are the Tresca bounds (used on Tresca edges), the normal forces'
/// bounds are those of `qp` (lower bound 0: unilateral); `levels` give the predictor (`nested`).
pub fn solve(qp: &Qp, nm: Coefficients, w: &[f64], lam0: &[f64], tol: f64, levels: (&Levels, usize)) -> Solved {
    let predict = || predicted(qp, nm, w, levels.0, tol);
    let warm = warm_sets(qp, nm, w, lam0);
    let first = if warm.is_some() {
        iterate(qp, (nm, w), lam0, warm.clone(), Some(&predict), tol, levels.1)
    } else {
        iterate(qp, (nm, w), lam0, predict(), None, tol, levels.1)
    };
    // the predicted sets are a start the iteration need not converge from (it is not globalised): where
    // it stops short, the plain iteration from λ₀ (its own sets) runs, with the iterations spent added
    first.or_else(|e| {
        let budget = levels.1.saturating_sub(e.iterations);
        iterate(qp, (nm, w), lam0, warm, None, tol, budget)
            .map(|(l, k, r)| (l, e.iterations + k, r))
            .map_err(|f| stalled(f.solver, e.iterations + f.iterations, f.residual))
    })
}

/// Active sets: per unknown its set, per edge the sign of the normal force in the threshold.
type Sets = (Vec<i8>, Vec<f64>);

/// The nested iteration's sets for the fine problem (`nested`; `None` without coarse levels or where a
/// level does not converge).
fn predicted(qp: &Qp, nm: Coefficients, w: &[f64], levels: &Levels, tol: f64) -> Option<Sets> {
    let nc = qp.d.len() / 2;
    let mut sets: Option<Sets> = None;
    for l in (1..=levels.len()).rev() {
        let co = levels.coarse(l, qp.c, qp.d, &qp.lo[nc..], w, nm);
        let cq = Qp { c: &co.c, d: &co.d, lo: &co.lo, hi: &co.hi };
        let start = sets.map(|(s, g)| (levels.prolong(l + 1, l, &s), levels.prolong(l + 1, l, &g)));
        let zero = vec![0.0; co.d.len()];
        let (lam, _, _) = iterate(&cq, (&co.coulomb, &co.w), &zero, start, None, tol, COARSE_ITER).ok()?;
        sets = Some(sets_of(&cq, &co.coulomb, &co.w, &lam, 1.0 - AT_BOUND));
    }
    sets.map(|(s, g)| (levels.prolong(1, 0, &s), levels.prolong(1, 0, &g)))
}

/// The iteration from λ₀ and the first sets `first` (`None`: those of λ₀'s residual); where the first
/// Newton step does not solve the problem, `retry` gives the sets of the second.
fn iterate(
    qp: &Qp,
    (nm, w): (Coefficients, &[f64]),
    lam0: &[f64],
    mut first: Option<Sets>,
    retry: Option<&dyn Fn() -> Option<Sets>>,
    tol: f64,
    max_iter: usize,
) -> Solved {
    let n = qp.d.len();
    let nc = n / 2;
    let mut lam: Vec<f64> = (0..n).map(|k| if k < nc { lam0[k] } else { lam0[k].max(qp.lo[k]) }).collect();
    let mut seen: HashSet<Vec<i8>> = HashSet::new();
    for it in 0..=max_iter {
        let ds = qp.slip_increment(&lam);
        let res = residual(qp, nm, w, &lam, &ds);
        if res <= tol {
            return Ok((lam, it, res));
        }
        if it == max_iter {
            return Err(stalled("coulomb ssn", it, res));
        }
        if it == 1 {
            first = retry.and_then(|r| r()).filter(|(s, _)| !seen.contains(s));
        }
        let (set, sigma_p) = first.take().unwrap_or_else(|| active_sets(qp, nm, w, &lam, &ds));
        if !seen.insert(set.clone()) {
            return Err(stalled("coulomb ssn (cycling: an active set repeated)", it, res));
        }
        lam =
            newton_step(qp, nm, w, &set, &sigma_p).ok_or_else(|| stalled("coulomb ssn (singular system)", it, res))?;
    }
    unreachable!("the loop returns at it == max_iter")
}

/// The sets of the warm start λ₀ itself, read from the forces alone (`None` if λ₀ = 0): separated
/// where a unilateral normal force is 0, slip where the friction force is at its threshold θ(P₀)
/// (to [`AT_BOUND`]), stick elsewhere; the sets of the step that λ₀ solved.
fn warm_sets(qp: &Qp, nm: Coefficients, w: &[f64], lam: &[f64]) -> Option<(Vec<i8>, Vec<f64>)> {
    (!lam.iter().all(|v| *v == 0.0)).then(|| sets_of(qp, nm, w, lam, 1.0 - AT_BOUND))
}

/// A friction force within this fraction of its threshold is at it (a slipping edge's force is its
/// threshold up to the rounding of the Newton step's LU solve).
const AT_BOUND: f64 = 1e-12;

/// The sets of the iterate λ with Δ = `ds`: those of y = λ + cΔ ([`sets_of`]).
fn active_sets(qp: &Qp, nm: Coefficients, w: &[f64], lam: &[f64], ds: &[f64]) -> (Vec<i8>, Vec<f64>) {
    let y: Vec<f64> = (0..lam.len()).map(|k| lam[k] + ds[k] / qp.c[(k, k)]).collect();
    sets_of(qp, nm, w, &y, 1.0)
}

/// Per unknown its set, from y (one value per unknown, tangential first): tangential 0 stick, ±1 slip
/// (|y_e| > `at` θ(y_n,e)), 2 free (θ = 0: μ = 0); normal 0 closed, 1 separated (unilateral, y_n,e ≤ 0).
/// And per edge the sign s of the normal force in the threshold F̄ s P.
fn sets_of(qp: &Qp, nm: Coefficients, w: &[f64], y: &[f64], at: f64) -> (Vec<i8>, Vec<f64>) {
    let n = y.len();
    let nc = n / 2;
    let mut set = vec![0i8; n];
    let mut sign = vec![1.0; nc];
    for e in 0..nc {
        let (yt, yn) = (y[e], y[nc + e]);
        let separated = qp.lo[nc + e] == 0.0 && yn <= 0.0;
        set[nc + e] = i8::from(separated);
        sign[e] = if yn < 0.0 { -1.0 } else { 1.0 };
        let theta = if separated && nm[e].is_some() { 0.0 } else { threshold(nm, w, e, yn) };
        set[e] = if theta == 0.0 {
            2
        } else if yt.abs() > at * theta {
            if yt > 0.0 {
                1
            } else {
                -1
            }
        } else {
            0
        };
    }
    (set, sign)
}

/// The iterate of the active sets `set` (one linear solve, dense LU).
fn newton_step(qp: &Qp, nm: Coefficients, w: &[f64], set: &[i8], sign: &[f64]) -> Option<Vec<f64>> {
    let n = set.len();
    let nc = n / 2;
    let mut a = DMatrix::zeros(n, n);
    let mut b = DVector::zeros(n);
    let row_of_c = |a: &mut DMatrix<f64>, b: &mut DVector<f64>, r: usize| {
        for j in 0..n {
            a[(r, j)] = qp.c[(r, j)];
        }
        b[r] = qp.d[r];
    };
    for e in 0..nc {
        let k = nc + e;
        match set[k] {
            1 => a[(k, k)] = 1.0,
            _ => row_of_c(&mut a, &mut b, k),
        }
        match (set[e], nm[e]) {
            (0, _) => row_of_c(&mut a, &mut b, e),
            (2, _) => a[(e, e)] = 1.0,
            (s, Some(f)) => {
                a[(e, e)] = 1.0;
                a[(e, k)] = -f64::from(s) * f * sign[e];
            }
            (s, None) => {
                a[(e, e)] = 1.0;
                b[e] = f64::from(s) * w[e];
            }
        }
    }
    let x = a.lu().solve(&b)?;
    x.iter().all(|v| v.is_finite()).then(|| x.iter().copied().collect())
}

/// The natural residual of both conditions, relative to the step's force scale: max over the normal
/// forces of |P − max(lo, P + Δ_n/C)| and over the friction forces of |μ − clamp(μ + Δs/C, ±θ(P))|.
fn residual(qp: &Qp, nm: Coefficients, w: &[f64], lam: &[f64], ds: &[f64]) -> f64 {
    let n = lam.len();
    let nc = n / 2;
    let mut r: f64 = 0.0;
    let mut scale: f64 = 0.0;
    for e in 0..nc {
        let k = nc + e;
        r = r.max((lam[k] - qp.project(k, lam[k] + ds[k] / qp.c[(k, k)])).abs());
        let theta = threshold(nm, w, e, lam[k]);
        r = r.max((lam[e] - (lam[e] + ds[e] / qp.c[(e, e)]).clamp(-theta, theta)).abs());
        scale = scale.max(qp.d[k].abs() / qp.c[(k, k)]);
        let t = qp.d[e].abs() / qp.c[(e, e)];
        scale = scale.max(if nm[e].is_some() { t } else { t.min(w[e]) });
    }
    if r == 0.0 {
        0.0
    } else {
        r / scale.max(f64::MIN_POSITIVE)
    }
}

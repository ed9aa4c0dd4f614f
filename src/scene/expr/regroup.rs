//! Products regrouped so that their time-dependent factors come last (`program::Builder::product`).
//!
//! exmex groups `35*(y^2)*(1-y)*(t+1)*cos(x)/52` as ((((35·y²)·(1−y))·(t+1))·cos x)/52, so everything
//! after (t+1) had to be redone at every time node; as (35·y²·(1−y)·cos x / 52)·(t+1) the spatial
//! factor is computed (or cached) once and a time node costs one product per term. This reassociates
//! products and divisions by time-independent values, so values move by a few ulps of the term
//! (tests/expr_exactness.rs: ≤ 1e-13 of the expression's size, measured 4.7e-15).

use super::sym::{Bin, Sym};

/// Factors of a product, each with `true` for a divisor.
pub(super) type Factors<'a> = Vec<(&'a Sym, bool)>;

/// The factors of the product at `s` (with `true` for a divisor) and, for each, whether it depends on
/// t; `None` unless there are factors of both kinds (then regrouping gains nothing).
pub(super) fn factors(s: &Sym) -> Option<(Factors<'_>, Vec<bool>)> {
    let mut factors = Vec::new();
    collect_factors(s, false, &mut factors);
    let timed: Vec<bool> = factors.iter().map(|(f, _)| has_t(f)).collect();
    (timed.contains(&true) && timed.contains(&false)).then_some((factors, timed))
}

/// The factors of the product tree at `s`: through products, and through divisions whose divisor does
/// not depend on t (pushed as divisors, `true`); anything else is one factor.
fn collect_factors<'a>(s: &'a Sym, divide: bool, out: &mut Vec<(&'a Sym, bool)>) {
    match s {
        Sym::Bin(Bin::Mul, a, b) if !divide => {
            collect_factors(a, false, out);
            collect_factors(b, false, out);
        }
        Sym::Bin(Bin::Div, a, b) if !divide && !has_t(b) => {
            collect_factors(a, false, out);
            out.push((b, true));
        }
        _ => out.push((s, divide)),
    }
}

/// True if the tree depends on t.
pub(super) fn has_t(s: &Sym) -> bool {
    match s {
        Sym::Num(_) => false,
        Sym::Var(v) => *v >= 2,
        Sym::Un(_, a) => has_t(a),
        Sym::Bin(_, a, b) => has_t(a) || has_t(b),
    }
}

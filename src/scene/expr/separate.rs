//! Separation of variables: an expression written as a sum of products of a time part and a space part,
//!   e(x, y, t) = Σ_j τ_j(t) s_j(x, y),
//! read off its tree, so that a load can be assembled once per distinct τ_j and combined at every time
//! node (`fem::loads`) instead of being evaluated at every quadrature point of every node.
//!
//! The split follows the tree: sums and differences split term by term, a product splits into the
//! products of its factors' parts, an integer power (2 to 8) of a sum into the products of its terms,
//! a division by a factor of one kind divides the parts of that kind, and a subtree that depends on t
//! only (or on x, y only) is one part as written. Time factors are kept as products of their atoms in
//! a canonical order, so t·(t+1), (t+1)·t and t²·… are recognised as equal. Anything else that
//! mixes x, y and t (`sin(x - t)`, `(x t)^2`, `max(x - t, 0)`) is not separated, and the whole
//! expression is then evaluated as before. Parts with structurally equal time factors are summed, so
//! `(t+1) a(x) + (t+1) b(x)` has one part; parts whose factors are equal only as functions (t + 1 and
//! 2 + 2t) stay apart and the load patterns sort that out numerically (`solve::superpose`).
//!
//! The separated form evaluates the same real function with the products and sums reassociated, so
//! values move by a few ulps of the terms (a test bounds this at 1e-14 of the terms' size).

use super::regroup::has_t;
use super::sym::{Bin, Sym, Un};

/// Largest number of parts a subtree may split into (a product of sums multiplies the counts).
const MAX_PARTS: usize = 64;

/// The parts (τ_j, s_j) of `s` with distinct time factors, in order of first appearance; `None` if
/// `s` does not separate. A time-independent expression is one part with τ = 1.
pub fn separate(s: &Sym) -> Option<Vec<(Sym, Sym)>> {
    let mut keys: Vec<String> = Vec::new();
    let mut merged: Vec<(Sym, Sym)> = Vec::new();
    for (mut atoms, space) in split(s)? {
        // the time factor as a product of its atoms in a canonical order, so that t·(t+1) and (t+1)·t,
        // or t² and t·t, are one factor
        let mut keyed: Vec<(String, Sym)> = atoms.drain(..).map(|a| (format!("{a:?}"), a)).collect();
        keyed.sort_by(|a, b| a.0.cmp(&b.0));
        let key = keyed.iter().map(|(k, _)| k.as_str()).collect::<Vec<_>>().join(" * ");
        let tau = keyed.into_iter().map(|(_, a)| a).reduce(|a, b| Sym::bin(Bin::Mul, a, b)).unwrap_or(Sym::Num(1.0));
        match keys.iter().position(|k| *k == key) {
            Some(i) => merged[i].1 = Sym::bin(Bin::Add, std::mem::take(&mut merged[i].1), space),
            None => {
                keys.push(key);
                merged.push((tau, space));
            }
        }
    }
    Some(merged)
}

/// The index of the time factor `tau` in `factors` (keyed by its tree), appended if new: how several
/// separated expressions share their distinct time factors (the loads' patterns, the exact solution of
/// the true errors).
pub fn factor_slot(factors: &mut Vec<(String, Sym)>, tau: Sym) -> usize {
    let key = format!("{tau:?}");
    factors.iter().position(|(k, _)| *k == key).unwrap_or_else(|| {
        factors.push((key, tau));
        factors.len() - 1
    })
}

/// True if the tree depends on x or y.
fn has_xy(s: &Sym) -> bool {
    match s {
        Sym::Num(_) => false,
        Sym::Var(v) => *v < 2,
        Sym::Un(_, a) => has_xy(a),
        Sym::Bin(_, a, b) => has_xy(a) || has_xy(b),
    }
}

/// a·b, without the factor 1 that the split introduces.
fn mul(a: &Sym, b: &Sym) -> Sym {
    match (a, b) {
        (Sym::Num(u), b) if *u == 1.0 => b.clone(),
        (a, Sym::Num(v)) if *v == 1.0 => a.clone(),
        (a, b) => Sym::bin(Bin::Mul, a.clone(), b.clone()),
    }
}

/// The integer exponent n ∈ [2, 8] of `b`, if it is one (larger powers are left whole).
fn small_power(b: &Sym) -> Option<usize> {
    match b {
        Sym::Num(v) if v.fract() == 0.0 && (2.0..=8.0).contains(v) => Some(*v as usize),
        _ => None,
    }
}

/// A part: the factors ("atoms") of its time part, and its space part.
type Part = (Vec<Sym>, Sym);

/// The atoms of a subtree that depends on t only: the factors of its products and integer powers
/// (numbers go to the space part, returned second).
fn atoms(s: &Sym, out: &mut Vec<Sym>) -> Sym {
    match s {
        Sym::Num(_) => s.clone(),
        Sym::Bin(Bin::Mul, a, b) => {
            let (ca, cb) = (atoms(a, out), atoms(b, out));
            mul(&ca, &cb)
        }
        Sym::Bin(Bin::Pow, a, b) if small_power(b).is_some() && !matches!(**a, Sym::Num(_)) => {
            let mut one = Vec::new();
            let c = atoms(a, &mut one);
            let n = small_power(b).unwrap_or(1);
            (0..n).for_each(|_| out.extend(one.iter().cloned()));
            (1..n).fold(c.clone(), |acc, _| mul(&acc, &c))
        }
        _ => {
            out.push(s.clone());
            Sym::Num(1.0)
        }
    }
}

fn negated(parts: Vec<Part>) -> Vec<Part> {
    parts.into_iter().map(|(tau, space)| (tau, Sym::un(Un::Neg, space))).collect()
}

/// All products of a part of `pa` with a part of `pb`; `None` beyond [`MAX_PARTS`].
fn cross(pa: &[Part], pb: &[Part]) -> Option<Vec<Part>> {
    (pa.len() * pb.len() <= MAX_PARTS).then(|| {
        pa.iter()
            .flat_map(|(ta, sa)| pb.iter().map(|(tb, sb)| ([ta.clone(), tb.clone()].concat(), mul(sa, sb))))
            .collect()
    })
}

/// The (time atoms, space) parts of `s`, unmerged.
fn split(s: &Sym) -> Option<Vec<Part>> {
    if !has_t(s) {
        return Some(vec![(Vec::new(), s.clone())]);
    }
    if !has_xy(s) {
        let mut a = Vec::new();
        let c = atoms(s, &mut a);
        return Some(vec![(a, c)]);
    }
    let parts = match s {
        Sym::Bin(Bin::Add, a, b) => [split(a)?, split(b)?].concat(),
        Sym::Bin(Bin::Sub, a, b) => [split(a)?, negated(split(b)?)].concat(),
        Sym::Un(Un::Neg, a) => negated(split(a)?),
        Sym::Bin(Bin::Mul, a, b) => cross(&split(a)?, &split(b)?)?,
        Sym::Bin(Bin::Pow, a, b) if small_power(b).is_some() => {
            let p = split(a)?;
            let n = small_power(b).unwrap_or(1);
            (1..n).try_fold(p.clone(), |acc, _| cross(&acc, &p))?
        }
        Sym::Bin(Bin::Div, a, b) if !has_t(b) => {
            split(a)?.into_iter().map(|(tau, space)| (tau, Sym::bin(Bin::Div, space, (**b).clone()))).collect()
        }
        Sym::Bin(Bin::Div, a, b) if !has_xy(b) => {
            let inv = Sym::bin(Bin::Div, Sym::Num(1.0), (**b).clone());
            split(a)?
                .into_iter()
                .map(|(mut tau, space)| {
                    tau.push(inv.clone());
                    (tau, space)
                })
                .collect()
        }
        _ => return None,
    };
    (parts.len() <= MAX_PARTS).then_some(parts)
}

#[cfg(test)]
mod tests {
    use super::super::Expr;
    use super::*;

    fn eval(s: &Sym, p: [f64; 3]) -> f64 {
        match s {
            Sym::Num(v) => *v,
            Sym::Var(i) => p[*i],
            Sym::Un(op, a) => op.apply(eval(a, p)),
            Sym::Bin(op, a, b) => op.apply(eval(a, p), eval(b, p)),
        }
    }

    fn parts(text: &str) -> Option<Vec<(Sym, Sym)>> {
        separate(Expr::parse("k", text).unwrap().tree())
    }

    #[test]
    fn separated_parts_sum_to_the_expression() {
        let cases = [
            ("35*(y^2)*(1-y)*(t+1)*cos(x)/52 + (t+1)*x - y*max(t-1/3, 0)/(t+2)", 2),
            ("x^2*y + 3", 1),
            ("t^2 + 1", 1),
            ("-(x*(t+1)) - (2*y - t)*(x + 1)", 3),
            ("(x + t)*(y - t)", 3),
            ("((t*x)/2 + 1)^4 + t*(x^2)*(t^2) - (t+1)*y*t", 6),
        ];
        for (text, n) in cases {
            let e = Expr::parse("k", text).unwrap();
            let p = separate(e.tree()).unwrap_or_else(|| panic!("{text} separates"));
            assert_eq!(p.len(), n, "{text}: {p:?}");
            assert!(p.iter().all(|(tau, s)| !has_xy(tau) && !has_t(s)), "{text}");
            for k in 0..50 {
                let q = [0.1 + 0.37 * k as f64, 0.2 + 0.11 * k as f64, 0.05 * k as f64];
                let terms: f64 = p.iter().map(|(tau, s)| (eval(tau, q) * eval(s, q)).abs()).sum();
                let sum: f64 = p.iter().map(|(tau, s)| eval(tau, q) * eval(s, q)).sum();
                // reassociated products and sums: a few ulps of the terms' size
                assert!((sum - eval(e.tree(), q)).abs() <= 1e-14 * terms.max(1e-300), "{text} at {q:?}");
            }
        }
    }

    #[test]
    fn mixed_subterms_do_not_separate() {
        for text in ["sin(x - t)", "(x*t)^0.5", "(x + t)^9", "max(x - t, 0)", "x/(x + t)", "exp(x*t) + t"] {
            assert!(parts(text).is_none(), "{text}");
        }
    }

    #[test]
    fn equal_time_factors_are_merged() {
        let p = parts("(t+1)*x + y*(t+1) - 2*(t+1)").unwrap();
        assert_eq!(p.len(), 1, "{p:?}");
    }
}

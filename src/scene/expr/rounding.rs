//! A bound on the rounding error of an expression's value in f64: running error analysis (Higham,
//! *Accuracy and Stability of Numerical Algorithms*, §3.3) along the expression tree ([`Sym`]), to
//! first order in the unit roundoff u = 2⁻⁵³. Each node carries its value v and a bound e on the error
//! it inherits from its operands and its own rounding:
//!
//! * a number: 0 for an integer below 2⁵³ (exact), else 2u|c| (its literal rounded to f64, or a constant
//!   folded from literals);
//! * a variable: 0 (x, y, t are the given points);
//! * `a ± b`: e_a + e_b + u|v|; `a·b`: |a|e_b + |b|e_a + e_a e_b + u|v|; `a/b`: (e_a + |v|e_b)/(|b| − e_b) + u|v|;
//! * `a^b`: |v|(|b|e_a/a + |ln a|e_b) + 2u|v| for a > 0 (powf, or the products it is compiled to), else
//!   for an integer b as a smooth function of a;
//! * a smooth function: |f'(a)|e_a + 2u|v| (libm is within an ulp), f' by a centred difference over at
//!   least e_a; `floor`, `round`, `ceil`, `trunc`, `signum`: the jump |f(a + e_a) − f(a − e_a)|.
//!
//! Where data cancel by rounding (`(0.1 + t)^2 - 0.01 - 0.2*t - t^2` is 1.7e-18 at t = 0, not 0) the
//! value lies within the bound of zero: `fem::lifting::consistency` compares data up to it.

use super::sym::{Bin, Sym, Un};

/// The unit roundoff of f64.
const U: f64 = f64::EPSILON / 2.0;

/// (value, rounding bound) of `s` at the variables `vars` = [x, y, t] (module doc); the bound is +∞
/// where the analysis does not apply (a division by an interval holding 0, a pole).
pub fn value_and_bound(s: &Sym, vars: [f64; 3]) -> (f64, f64) {
    match s {
        Sym::Num(c) if c.fract() == 0.0 && c.abs() < 2f64.powi(53) => (*c, 0.0),
        Sym::Num(c) => (*c, 2.0 * U * c.abs()),
        Sym::Var(i) => (vars[*i], 0.0),
        Sym::Un(op, a) => {
            let (a, ea) = value_and_bound(a, vars);
            let v = op.apply(a);
            (v, finite_or_inf(unary(*op, a, ea, v)))
        }
        Sym::Bin(op, a, b) => {
            let ((a, ea), (b, eb)) = (value_and_bound(a, vars), value_and_bound(b, vars));
            let v = op.apply(a, b);
            (v, finite_or_inf(binary(*op, (a, ea), (b, eb), v)))
        }
    }
}

fn finite_or_inf(e: f64) -> f64 {
    if e.is_nan() {
        f64::INFINITY
    } else {
        e
    }
}

fn unary(op: Un, a: f64, ea: f64, v: f64) -> f64 {
    match op {
        Un::Neg | Un::Abs => ea,
        Un::Floor | Un::Round | Un::Ceil | Un::Trunc | Un::Signum => (op.apply(a + ea) - op.apply(a - ea)).abs(),
        Un::Fract => ea.max((op.apply(a + ea) - op.apply(a - ea)).abs()),
        _ => slope(|x| op.apply(x), a, ea) * ea + 2.0 * U * v.abs(),
    }
}

fn binary(op: Bin, (a, ea): (f64, f64), (b, eb): (f64, f64), v: f64) -> f64 {
    let own = U * v.abs();
    match op {
        Bin::Add | Bin::Sub => ea + eb + own,
        Bin::Mul => a.abs() * eb + b.abs() * ea + ea * eb + own,
        Bin::Div if b.abs() > eb => (ea + v.abs() * eb) / (b.abs() - eb) + own,
        Bin::Div => f64::INFINITY,
        Bin::Pow if a > 0.0 => v.abs() * (b.abs() * ea / a + a.ln().abs() * eb) + 2.0 * own,
        Bin::Pow if b.fract() == 0.0 => slope(|x| x.powf(b), a, ea) * ea + 2.0 * own,
        Bin::Pow => f64::INFINITY,
        Bin::Atan2 if a * a + b * b > 0.0 => (b.abs() * ea + a.abs() * eb) / (a * a + b * b) + 2.0 * own,
        Bin::Atan2 => f64::INFINITY,
        Bin::Min | Bin::Max => ea.max(eb),
    }
}

/// |f'(a)| by a centred difference over h = max(e, 1e-8|a|) (one-sided at the edge of f's domain),
/// +∞ where neither side is finite.
fn slope(f: impl Fn(f64) -> f64, a: f64, e: f64) -> f64 {
    let h = e.max(1e-8 * a.abs()).max(f64::MIN_POSITIVE);
    let (lo, mid, hi) = (f(a - h), f(a), f(a + h));
    let d = [(hi - lo) / (2.0 * h), (hi - mid) / h, (mid - lo) / h].into_iter().find(|d| d.is_finite());
    d.map_or(f64::INFINITY, f64::abs)
}

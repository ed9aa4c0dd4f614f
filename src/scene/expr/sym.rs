//! Expression trees read off exmex by symbolic evaluation.
//!
//! exmex keeps its parse tree private, but it evaluates over any value type with operators from a
//! factory. [`SymOps`] mirrors exmex's [`FloatOpsFactory`] operator for operator (same symbols, same
//! priorities, same unary/binary roles), except that an operator applied to a [`Sym`] builds a tree
//! node instead of a number. Evaluating the parsed expression on the symbolic variables x, y, t
//! therefore records exactly the operations, in exactly the order and grouping, that exmex's own
//! interpreter performs — precedence is exmex's, not re-implemented here. Operations on two numbers
//! are carried out at once with the same `f64` functions as exmex's (which folds them the same way
//! when it compiles), so constant subterms have exmex's bits.

use exmex::{BinOp, FloatOpsFactory, MakeOperators, Operator};
use std::f64::consts::{E, PI, TAU};
use std::str::FromStr;
use std::sync::Arc;

/// Unary functions (exmex's names in [`Un::apply`]'s comments).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Un {
    Neg,
    Abs,
    Signum,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Floor,
    Round,
    Ceil,
    Trunc,
    Fract,
    Exp,
    Sqrt,
    Cbrt,
    /// `ln` and `log`
    Ln,
    Log2,
    Log10,
}

impl Un {
    /// The value, with the same `f64` method as exmex's factory.
    #[inline(always)]
    pub fn apply(self, a: f64) -> f64 {
        match self {
            Un::Neg => -a,
            Un::Abs => a.abs(),
            Un::Signum => a.signum(),
            Un::Sin => a.sin(),
            Un::Cos => a.cos(),
            Un::Tan => a.tan(),
            Un::Asin => a.asin(),
            Un::Acos => a.acos(),
            Un::Atan => a.atan(),
            Un::Sinh => a.sinh(),
            Un::Cosh => a.cosh(),
            Un::Tanh => a.tanh(),
            Un::Asinh => a.asinh(),
            Un::Acosh => a.acosh(),
            Un::Atanh => a.atanh(),
            Un::Floor => a.floor(),
            Un::Round => a.round(),
            Un::Ceil => a.ceil(),
            Un::Trunc => a.trunc(),
            Un::Fract => a.fract(),
            Un::Exp => a.exp(),
            Un::Sqrt => a.sqrt(),
            Un::Cbrt => a.cbrt(),
            Un::Ln => a.ln(),
            Un::Log2 => a.log2(),
            Un::Log10 => a.log10(),
        }
    }
}

/// Binary operations.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Bin {
    Add,
    Sub,
    Mul,
    Div,
    /// `a^b` = powf (integer exponents become products when compiled)
    Pow,
    Atan2,
    Min,
    Max,
}

impl Bin {
    /// The value, with the same `f64` method as exmex's factory.
    #[inline(always)]
    pub fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Bin::Add => a + b,
            Bin::Sub => a - b,
            Bin::Mul => a * b,
            Bin::Div => a / b,
            Bin::Pow => a.powf(b),
            Bin::Atan2 => a.atan2(b),
            Bin::Min => a.min(b),
            Bin::Max => a.max(b),
        }
    }
}

/// A symbolic value: a number, a variable (0 = x, 1 = y, 2 = t) or an operation on symbolic values.
#[derive(Clone, Debug)]
pub enum Sym {
    Num(f64),
    Var(usize),
    Un(Un, Arc<Sym>),
    Bin(Bin, Arc<Sym>, Arc<Sym>),
}

impl Default for Sym {
    fn default() -> Self {
        Sym::Num(0.0)
    }
}

/// Literals, as exmex's `f64` reads them.
impl FromStr for Sym {
    type Err = std::num::ParseFloatError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        s.parse::<f64>().map(Sym::Num)
    }
}

impl Sym {
    /// `op a`, computed when a is a number.
    pub fn un(op: Un, a: Sym) -> Sym {
        match a {
            Sym::Num(v) => Sym::Num(op.apply(v)),
            a => Sym::Un(op, Arc::new(a)),
        }
    }

    /// `a op b`, computed when both are numbers.
    pub fn bin(op: Bin, a: Sym, b: Sym) -> Sym {
        match (a, b) {
            (Sym::Num(u), Sym::Num(v)) => Sym::Num(op.apply(u, v)),
            (a, b) => Sym::Bin(op, Arc::new(a), Arc::new(b)),
        }
    }
}

/// exmex's float operators ([`FloatOpsFactory`]) acting on [`Sym`]: same symbols, priorities and
/// roles, in the same order (a test compares the two lists).
#[derive(Clone, Debug)]
pub struct SymOps;

fn bin(repr: &str, prio: i64, is_commutative: bool, apply: fn(Sym, Sym) -> Sym) -> Operator<'_, Sym> {
    Operator::make_bin(repr, BinOp { apply, prio, is_commutative })
}

impl MakeOperators<Sym> for SymOps {
    fn make<'a>() -> Vec<Operator<'a, Sym>> {
        let u = |repr: &'a str, f: fn(Sym) -> Sym| Operator::make_unary(repr, f);
        let c = |repr: &'a str, v: f64| Operator::make_constant(repr, Sym::Num(v));
        vec![
            bin("^", 4, false, |a, b| Sym::bin(Bin::Pow, a, b)),
            bin("*", 2, true, |a, b| Sym::bin(Bin::Mul, a, b)),
            bin("/", 3, false, |a, b| Sym::bin(Bin::Div, a, b)),
            Operator::make_bin_unary(
                "+",
                BinOp { apply: |a, b| Sym::bin(Bin::Add, a, b), prio: 0, is_commutative: true },
                |a| a,
            ),
            Operator::make_bin_unary(
                "-",
                BinOp { apply: |a, b| Sym::bin(Bin::Sub, a, b), prio: 1, is_commutative: false },
                |a| Sym::un(Un::Neg, a),
            ),
            bin("atan2", 0, false, |a, b| Sym::bin(Bin::Atan2, a, b)),
            bin("min", 0, false, |a, b| Sym::bin(Bin::Min, a, b)),
            bin("max", 0, false, |a, b| Sym::bin(Bin::Max, a, b)),
            u("abs", |a| Sym::un(Un::Abs, a)),
            u("signum", |a| Sym::un(Un::Signum, a)),
            u("sin", |a| Sym::un(Un::Sin, a)),
            u("cos", |a| Sym::un(Un::Cos, a)),
            u("tan", |a| Sym::un(Un::Tan, a)),
            u("asin", |a| Sym::un(Un::Asin, a)),
            u("acos", |a| Sym::un(Un::Acos, a)),
            u("atan", |a| Sym::un(Un::Atan, a)),
            u("sinh", |a| Sym::un(Un::Sinh, a)),
            u("cosh", |a| Sym::un(Un::Cosh, a)),
            u("tanh", |a| Sym::un(Un::Tanh, a)),
            u("asinh", |a| Sym::un(Un::Asinh, a)),
            u("acosh", |a| Sym::un(Un::Acosh, a)),
            u("atanh", |a| Sym::un(Un::Atanh, a)),
            u("floor", |a| Sym::un(Un::Floor, a)),
            u("round", |a| Sym::un(Un::Round, a)),
            u("ceil", |a| Sym::un(Un::Ceil, a)),
            u("trunc", |a| Sym::un(Un::Trunc, a)),
            u("fract", |a| Sym::un(Un::Fract, a)),
            u("exp", |a| Sym::un(Un::Exp, a)),
            u("sqrt", |a| Sym::un(Un::Sqrt, a)),
            u("cbrt", |a| Sym::un(Un::Cbrt, a)),
            u("ln", |a| Sym::un(Un::Ln, a)),
            u("log2", |a| Sym::un(Un::Log2, a)),
            u("log10", |a| Sym::un(Un::Log10, a)),
            u("log", |a| Sym::un(Un::Ln, a)),
            c("PI", PI),
            c("π", PI),
            c("E", E),
            c("e", E),
            c("TAU", TAU),
            c("τ", TAU),
        ]
    }
}

/// An operator's symbol, (priority, commutative) if binary, whether unary, its value if a constant.
pub type Signature = (String, Option<(i64, bool)>, bool, Option<f64>);

/// The operator table exmex parses with, for the test that [`SymOps`] mirrors it.
pub fn float_ops_signature() -> Vec<Signature> {
    signature(&FloatOpsFactory::<f64>::make(), |v| *v)
}

/// [`SymOps`]'s table in the same form.
pub fn sym_ops_signature() -> Vec<Signature> {
    signature(&SymOps::make(), |v| match v {
        Sym::Num(v) => *v,
        _ => f64::NAN,
    })
}

fn signature<T: Clone>(ops: &[Operator<'_, T>], num: impl Fn(&T) -> f64) -> Vec<Signature> {
    ops.iter()
        .map(|o| {
            let bin = o.bin().ok().map(|b| (b.prio, b.is_commutative));
            (o.repr().to_string(), bin, o.has_unary(), o.constant().map(|c| num(&c)))
        })
        .collect()
}

//! Scalar expressions f(x, y, t) from scene strings: parsed by the `exmex` crate, compiled once into a
//! straight-line program, evaluated over many points at a time.
//!
//! Only the variables `x`, `y` and `t` are allowed; anything else is rejected when the scene is read.
//! Reading: [`lint`] rejects the constructs exmex reads unlike mathematics; exmex parses, and the
//! expression tree is recorded by evaluating exmex's parse on symbolic values ([`sym`]), so precedence and
//! grouping are exactly exmex's. Compiling ([`program`]): shared subexpressions computed once, integer
//! powers as products, constants folded, t-only parts once per call, the rest in batches of points.
//! Values agree with exmex's interpreter ([`Interpreted`], kept as the reference) to a few ulps (a test
//! checks every expression of `verification/cases/` at its quadrature points).
//! Every evaluation is checked for finiteness, so a division by zero or `sqrt(-1)` at a quadrature point
//! becomes an error naming the expression and the point instead of a NaN in the results.
//!
//! ```
//! use tresca_cr::scene::expr::{Expr, ExprSet};
//! let e = Expr::parse("f", "-(x^2) + 1.5e-1*sin(pi*t)")?; // -x^2 is refused: exmex reads (-x)^2
//! assert!((e.eval(2.0, 3.0, 0.5)? - (-4.0 + 0.15)).abs() < 1e-12 && Expr::parse("f", "-x^2").is_err());
//! let (set, mut out) = (ExprSet::new(&[&e, &Expr::parse("g", "x*y")?]), Vec::new());
//! set.eval(&[[0.0, 1.0], [2.0, 3.0]], 0.0, &mut out)?;
//! assert_eq!(out, vec![0.0, 0.0, -4.0, 6.0]); // point-major (sin(πt) = 0 at t = 0)
//! assert!(Expr::parse("h", "1/x")?.eval(0.0, 0.0, 0.0).is_err()); // an error, not a NaN
//! # Ok::<(), tresca_cr::Error>(())
//! ```

mod eval;
mod lint;
pub mod program;
mod regroup;
pub mod rounding;
mod separate;
mod set;
pub use separate::factor_slot;
pub use set::{BoundSet, ExprSet};
pub mod sym;

use crate::error::{Error, Result};
use exmex::prelude::*;
use lint::lint;
use program::Program;
use std::sync::Arc;
use sym::{Sym, SymOps};

/// A compiled expression in (x, y, t).
#[derive(Clone, Debug)]
pub struct Expr {
    key: String,
    text: String,
    /// The text as handed to exmex (see `lint`).
    normalised: String,
    tree: Arc<Sym>,
    program: Arc<Program>,
    /// Which of x, y, t occur.
    uses: [bool; 3],
    constant: Option<f64>,
}

impl Expr {
    /// Parse `text` (scene key `key`, used in messages).
    pub fn parse(key: &str, text: &str) -> Result<Self> {
        let err = |msg: String| Error::Expr { key: key.to_string(), expr: text.to_string(), msg };
        if text.trim().is_empty() {
            return Err(err("empty expression".into()));
        }
        let normalised = lint(text).map_err(err)?;
        let flat = FlatEx::<Sym, SymOps>::parse(&normalised).map_err(|e| err(format!("cannot parse: {e}")))?;
        let vars = slots(flat.var_names()).map_err(err)?;
        let mut uses = [false; 3];
        vars.iter().for_each(|&s| uses[s] = true);
        let symbols: Vec<Sym> = vars.iter().map(|&s| Sym::Var(s)).collect();
        let tree = flat.eval(&symbols).map_err(|e| err(format!("cannot evaluate: {e}")))?;
        let constant = match tree {
            Sym::Num(v) if vars.is_empty() => {
                if !v.is_finite() {
                    return Err(err(format!("evaluates to {v}")));
                }
                Some(v)
            }
            _ => None,
        };
        let program = Arc::new(Program::new(&[&tree]));
        Ok(Expr {
            key: key.to_string(),
            text: text.to_string(),
            normalised,
            tree: Arc::new(tree),
            program,
            uses,
            constant,
        })
    }

    /// The constant value if the expression has no variables.
    pub fn constant(&self) -> Option<f64> {
        self.constant
    }

    /// True if the expression is the constant zero (such a term is not assembled).
    pub fn is_zero(&self) -> bool {
        self.constant == Some(0.0)
    }

    /// True if the expression depends on `t`.
    pub fn depends_on_t(&self) -> bool {
        self.uses[2]
    }

    /// The expression tree (as exmex groups it).
    pub fn tree(&self) -> &Sym {
        &self.tree
    }

    /// The parts (τ_j(t), s_j(x, y)) with e = Σ_j τ_j s_j and distinct τ_j, if the expression separates
    /// ([`separate`]).
    pub fn separate(&self) -> Option<Vec<(Sym, Sym)>> {
        separate::separate(&self.tree)
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// An error about this expression (its scene key and text).
    pub fn error(&self, msg: String) -> Error {
        Error::Expr { key: self.key.clone(), expr: self.text.clone(), msg }
    }

    /// A bound on the rounding error of the value at (x, y, t) ([`rounding`]).
    pub fn rounding(&self, x: f64, y: f64, t: f64) -> f64 {
        rounding::value_and_bound(&self.tree, [x, y, t]).1
    }

    /// Evaluate at (x, y, t); a non-finite value is an error.
    pub fn eval(&self, x: f64, y: f64, t: f64) -> Result<f64> {
        if let Some(c) = self.constant {
            return Ok(c);
        }
        let mut v = [0.0];
        self.program.eval_point(x, y, t, &mut v);
        check(self, v[0], [x, y], t)?;
        Ok(v[0])
    }

    /// exmex's own interpreter for this expression: the reference the compiled program is checked
    /// against (tests, benchmarks); not used by runs.
    pub fn interpreted(&self) -> Result<Interpreted> {
        let flat = exmex::parse::<f64>(&self.normalised).map_err(|e| self.error(format!("cannot parse: {e}")))?;
        let slots = slots(flat.var_names()).map_err(|m| self.error(m))?;
        Ok(Interpreted { flat: Box::new(flat), slots })
    }
}

/// Variable slots (0 = x, 1 = y, 2 = t) of exmex's variables, in its (alphabetical) order.
fn slots(names: &[String]) -> std::result::Result<Vec<usize>, String> {
    names
        .iter()
        .map(|name| match name.as_str() {
            "x" => Ok(0),
            "y" => Ok(1),
            "t" => Ok(2),
            other => Err(format!("unknown variable `{other}` (allowed: x, y, t)")),
        })
        .collect()
}

/// A non-finite value of `e` at the point is an error naming both.
fn check(e: &Expr, v: f64, p: [f64; 2], t: f64) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(e.error(format!("value {v} at (x={}, y={}, t={t})", p[0], p[1])))
    }
}

/// An expression evaluated by exmex's interpreter (what runs used before compilation).
pub struct Interpreted {
    /// Boxed: exmex's FlatEx keeps ~20 kB of inline storage.
    flat: Box<FlatEx<f64>>,
    slots: Vec<usize>,
}

impl Interpreted {
    /// The value at (x, y, t), unchecked (NaN if exmex reports an error).
    pub fn eval(&self, x: f64, y: f64, t: f64) -> f64 {
        let all = [x, y, t];
        let mut vals = [0.0; 3];
        for (v, &s) in vals.iter_mut().zip(&self.slots) {
            *v = all[s];
        }
        self.flat.eval(&vals[..self.slots.len()]).unwrap_or(f64::NAN)
    }
}

/// A vector expression (two components).
#[derive(Clone, Debug)]
pub struct Vec2Expr(pub [Expr; 2]);

impl Vec2Expr {
    /// Parse two component strings; `key` names the scene entry.
    pub fn parse(key: &str, comps: &[String; 2]) -> Result<Self> {
        Ok(Vec2Expr([Expr::parse(&format!("{key}[0]"), &comps[0])?, Expr::parse(&format!("{key}[1]"), &comps[1])?]))
    }
    /// Evaluate both components.
    pub fn eval(&self, x: f64, y: f64, t: f64) -> Result<[f64; 2]> {
        Ok([self.0[0].eval(x, y, t)?, self.0[1].eval(x, y, t)?])
    }
    /// The rounding bounds of both components ([`Expr::rounding`]).
    pub fn rounding(&self, x: f64, y: f64, t: f64) -> [f64; 2] {
        [self.0[0].rounding(x, y, t), self.0[1].rounding(x, y, t)]
    }
    /// True if both components are the constant zero.
    pub fn is_zero(&self) -> bool {
        self.0[0].is_zero() && self.0[1].is_zero()
    }
    /// True if a component depends on `t`.
    pub fn depends_on_t(&self) -> bool {
        self.0[0].depends_on_t() || self.0[1].depends_on_t()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variables_in_any_order_map_to_xyt() {
        let e = Expr::parse("k", "t*100 + y*10 + x").unwrap();
        assert_eq!(e.eval(1.0, 2.0, 3.0).unwrap(), 321.0);
        let e = Expr::parse("k", "y - x").unwrap();
        assert_eq!(e.eval(1.0, 5.0, 0.0).unwrap(), 4.0);
    }

    #[test]
    fn unknown_variable_is_rejected_with_its_name() {
        let e = Expr::parse("loads.f[0]", "x + z").unwrap_err().to_string();
        assert!(e.contains("unknown variable `z`") && e.contains("loads.f[0]"), "{e}");
    }

    #[test]
    fn non_finite_value_is_an_error() {
        let e = Expr::parse("g", "1/x").unwrap();
        assert!(e.eval(0.0, 0.0, 0.0).is_err());
        assert!(Expr::parse("g", "1/0").is_err());
    }

    #[test]
    fn precedence_matches_mathematics_or_is_rejected() {
        let v = |s: &str| Expr::parse("k", s).unwrap().eval(3.0, 2.0, 0.5).unwrap();
        assert_eq!(v("-2*x"), -6.0);
        assert_eq!(v("x*(-y)"), -6.0);
        assert_eq!(v("x - y - 1"), 0.0);
        assert_eq!(v("x / y / 3"), 0.5);
        assert_eq!(v("x/y*4"), 6.0);
        assert_eq!(v("1 - x*y + 2"), -3.0);
        assert_eq!(v("x*y^2/4"), 3.0);
        assert_eq!(v("-(x^2)"), -9.0);
        assert_eq!(v("(-x)^2"), 9.0);
        assert_eq!(v("2^(x^2)"), 512.0);
        assert_eq!(v("1e-3*x"), 0.003);
        assert_eq!(v("2.5E+2 + 1e2*y"), 450.0);
        assert_eq!(v("exp(-x)"), (-3.0f64).exp());
        assert_eq!(v("x*y - x^2"), -3.0);
        assert_eq!(v("max(0, x)*min(y, 1) + max(x, y)"), 6.0);
        for bad in ["-x^2", "-sin(t)^2", "2^x^2", "(1 + -x^2)", "min(-x^2, 1)", "-(x)^2"] {
            let e = Expr::parse("k", bad).unwrap_err().to_string();
            assert!(e.contains("exmex reads"), "{bad}: {e}");
        }
        for bad in ["max(0, min(1, x))", "min(x, 2*max(y, 1))"] {
            let e = Expr::parse("k", bad).unwrap_err().to_string();
            assert!(e.contains("cannot nest"), "{bad}: {e}");
        }
    }

    #[test]
    fn symbolic_operators_mirror_exmex() {
        assert_eq!(sym::sym_ops_signature(), sym::float_ops_signature());
    }

    #[test]
    fn compiled_matches_point_and_interpreted_evaluation() {
        // integer powers (positive, negative, zero), shared subterms, t-only parts, constant outputs
        let texts = ["x^3*y^-2 + (x^3)*t", "(1-y)^2*max(t-1/3, 0) + cos(x)*(1-y)^2", "t^2 + 1", "x", "2.5", "sin(x*y)"];
        let exprs: Vec<Expr> = texts.iter().map(|s| Expr::parse("k", s).unwrap()).collect();
        let set = ExprSet::new(&exprs.iter().collect::<Vec<_>>());
        let pts: Vec<[f64; 2]> = (0..100).map(|i| [0.1 + i as f64 * 0.37, 0.5 + (i % 7) as f64]).collect();
        let mut out = Vec::new();
        set.eval(&pts, 0.75, &mut out).unwrap();
        // bound to the points (spatial parts cached): the same bits
        let mut bound_out = Vec::new();
        set.clone().bind(pts.clone()).eval(0.75, &mut bound_out).unwrap();
        assert!(out.iter().zip(&bound_out).all(|(a, b)| a.to_bits() == b.to_bits()) && out.len() == bound_out.len());
        for (i, p) in pts.iter().enumerate() {
            for (k, e) in exprs.iter().enumerate() {
                let v = out[i * exprs.len() + k];
                // batch and point evaluation perform the same operations: bit-identical
                assert_eq!(v.to_bits(), e.eval(p[0], p[1], 0.75).unwrap().to_bits(), "{}", texts[k]);
                // products for integer powers: a few roundings, far below 1e-14 relative
                let r = e.interpreted().unwrap().eval(p[0], p[1], 0.75);
                assert!((v - r).abs() <= 1e-14 * r.abs(), "{}: {v} vs {r}", texts[k]);
            }
        }
        // a non-finite value names the expression and the first point that has one
        let bad = ExprSet::new(&[&exprs[0], &Expr::parse("g", "1/(x-0.47)").unwrap()]);
        let e = bad.eval(&pts, 0.0, &mut out).unwrap_err().to_string();
        assert!(e.contains("1/(x-0.47)") && e.contains("value inf at (x=0.47"), "{e}");
    }

    #[test]
    fn constants_and_zero_detection() {
        assert!(Expr::parse("f", "0").unwrap().is_zero());
        assert!(!Expr::parse("f", "0*x").unwrap().is_zero());
        let pi = Expr::parse("f", "PI").unwrap().constant().unwrap();
        assert!((pi - std::f64::consts::PI).abs() < 1e-15);
        assert_eq!(Expr::parse("f", "2*pi").unwrap().constant(), Some(2.0 * std::f64::consts::PI));
    }
}

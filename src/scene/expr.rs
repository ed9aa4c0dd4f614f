//! Scalar expressions f(x, y, t) from scene strings, compiled once with the `exmex` crate.
//!
//! Only the variables `x`, `y` and `t` are allowed; anything else is rejected when the scene is read.
//! Every evaluation is checked for finiteness, so a division by zero or `sqrt(-1)` at a quadrature point
//! becomes an error naming the expression and the point instead of a NaN in the results.

use crate::error::{Error, Result};
use exmex::prelude::*;

/// A compiled expression in (x, y, t).
#[derive(Clone, Debug)]
pub struct Expr {
    key: String,
    text: String,
    /// Boxed: exmex's FlatEx keeps ~20 kB of inline storage.
    flat: Box<FlatEx<f64>>,
    /// For each of the expression's variables (in exmex's alphabetical order): 0 = x, 1 = y, 2 = t.
    slots: Vec<usize>,
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
        let flat = exmex::parse::<f64>(&normalised).map_err(|e| err(format!("cannot parse: {e}")))?;
        let mut slots = Vec::new();
        for name in flat.var_names() {
            slots.push(match name.as_str() {
                "x" => 0,
                "y" => 1,
                "t" => 2,
                other => return Err(err(format!("unknown variable `{other}` (allowed: x, y, t)"))),
            });
        }
        let constant = if slots.is_empty() {
            let v = flat.eval(&[]).map_err(|e| err(format!("cannot evaluate: {e}")))?;
            if !v.is_finite() {
                return Err(err(format!("evaluates to {v}")));
            }
            Some(v)
        } else {
            None
        };
        Ok(Expr { key: key.to_string(), text: text.to_string(), flat: Box::new(flat), slots, constant })
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
        self.slots.contains(&2)
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// An error about this expression (its scene key and text).
    pub fn error(&self, msg: String) -> Error {
        Error::Expr { key: self.key.clone(), expr: self.text.clone(), msg }
    }

    /// Evaluate at (x, y, t); a non-finite value is an error.
    pub fn eval(&self, x: f64, y: f64, t: f64) -> Result<f64> {
        if let Some(c) = self.constant {
            return Ok(c);
        }
        let all = [x, y, t];
        let mut vals = [0.0; 3];
        for (v, &s) in vals.iter_mut().zip(&self.slots) {
            *v = all[s];
        }
        let v = self.flat.eval(&vals[..self.slots.len()]).map_err(|e| Error::Expr {
            key: self.key.clone(),
            expr: self.text.clone(),
            msg: format!("cannot evaluate at (x={x}, y={y}, t={t}): {e}"),
        })?;
        if !v.is_finite() {
            return Err(Error::Expr {
                key: self.key.clone(),
                expr: self.text.clone(),
                msg: format!("value {v} at (x={x}, y={y}, t={t})"),
            });
        }
        Ok(v)
    }
}

/// Reject the two constructs whose exmex reading differs from the usual mathematical one:
/// a unary minus in front of a power (exmex reads `-x^2` as `(-x)^2`) and chained powers
/// (exmex reads `2^x^2` as `(2^x)^2`). Both must be parenthesised explicitly.
/// Returns the text with scientific-notation literals (`1.2e-3`, which exmex cannot read) written out.
fn lint(text: &str) -> std::result::Result<String, String> {
    let mut out = String::with_capacity(text.len());
    #[derive(Clone, Copy, PartialEq)]
    enum Tok {
        Atom,
        Ident,
        /// min, max, atan2: exmex's two-argument functions, which it cannot nest
        Binary,
        Open,
        Close,
        Comma,
        Op(char),
    }
    let mut toks = Vec::new();
    let mut chars = text.chars().peekable();
    while let Some(&c) = chars.peek() {
        if c.is_whitespace() {
            out.push(c);
            chars.next();
        } else if c.is_ascii_digit() || c == '.' {
            let mut lit = String::new();
            while let Some(d) = chars.next_if(|d| d.is_ascii_digit() || *d == '.') {
                lit.push(d);
            }
            // exponent notation such as 1e-3
            if chars.peek().is_some_and(|d| *d == 'e' || *d == 'E') {
                let mut look = chars.clone();
                look.next();
                let sign = look.next_if(|d| *d == '-' || *d == '+');
                if look.peek().is_some_and(|d| d.is_ascii_digit()) {
                    chars.next();
                    lit.push('e');
                    if let Some(sg) = sign {
                        chars.next();
                        lit.push(sg);
                    }
                    while let Some(d) = chars.next_if(|d| d.is_ascii_digit()) {
                        lit.push(d);
                    }
                }
            }
            let v: f64 = lit.parse().map_err(|_| format!("malformed number `{lit}`"))?;
            if lit.contains('e') {
                // Rust's Display never uses exponent notation and round-trips exactly
                out.push_str(&format!("{v}"));
            } else {
                out.push_str(&lit);
            }
            toks.push(Tok::Atom);
        } else if c.is_alphanumeric() || c == '_' {
            let mut name = String::new();
            while let Some(d) = chars.next_if(|d| d.is_alphanumeric() || *d == '_') {
                name.push(d);
            }
            // `pi` is accepted for exmex's `PI`
            out.push_str(if name == "pi" { "PI" } else { &name });
            toks.push(if matches!(name.as_str(), "min" | "max" | "atan2") { Tok::Binary } else { Tok::Ident });
        } else {
            out.push(c);
            chars.next();
            toks.push(match c {
                '(' => Tok::Open,
                ')' => Tok::Close,
                ',' => Tok::Comma,
                other => Tok::Op(other),
            });
        }
    }
    // index just past the operand starting at i (atom, identifier, call or parenthesised group)
    let skip_operand = |i: usize| -> usize {
        let mut j = i;
        if matches!(toks.get(j), Some(Tok::Ident | Tok::Binary)) && toks.get(j + 1) == Some(&Tok::Open) {
            j += 1;
        }
        if toks.get(j) == Some(&Tok::Open) {
            let mut depth = 0;
            while j < toks.len() {
                match toks[j] {
                    Tok::Open => depth += 1,
                    Tok::Close => {
                        depth -= 1;
                        if depth == 0 {
                            return j + 1;
                        }
                    }
                    _ => {}
                }
                j += 1;
            }
            return j;
        }
        j + 1
    };
    // depth of parentheses at which each open two-argument call started
    let mut calls: Vec<usize> = Vec::new();
    let mut depth = 0usize;
    for t in &toks {
        match t {
            Tok::Open => depth += 1,
            Tok::Close => {
                depth = depth.saturating_sub(1);
                if calls.last() == Some(&depth) {
                    calls.pop();
                }
            }
            Tok::Binary => {
                if !calls.is_empty() {
                    return Err("exmex cannot nest min/max/atan2 inside another min/max/atan2; \
                                write max(a, b) as (a + b + abs(a - b))/2"
                        .into());
                }
                calls.push(depth);
            }
            _ => {}
        }
    }
    for i in 0..toks.len() {
        let unary = toks[i] == Tok::Op('-') && (i == 0 || matches!(toks[i - 1], Tok::Open | Tok::Comma | Tok::Op(_)));
        if unary && toks.get(skip_operand(i + 1)) == Some(&Tok::Op('^')) {
            return Err(
                "ambiguous unary minus before a power: exmex reads -a^b as (-a)^b; write -(a^b) or (-a)^b".into()
            );
        }
        if toks[i] == Tok::Op('^') {
            let mut j = i + 1;
            while toks.get(j).is_some_and(|t| matches!(t, Tok::Op('-') | Tok::Op('+'))) {
                j += 1;
            }
            if toks.get(skip_operand(j)) == Some(&Tok::Op('^')) {
                return Err("chained powers: exmex reads a^b^c as (a^b)^c; parenthesise, e.g. a^(b^c)".into());
            }
        }
    }
    Ok(out)
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
    fn constants_and_zero_detection() {
        assert!(Expr::parse("f", "0").unwrap().is_zero());
        assert!(!Expr::parse("f", "0*x").unwrap().is_zero());
        let pi = Expr::parse("f", "PI").unwrap().constant().unwrap();
        assert!((pi - std::f64::consts::PI).abs() < 1e-15);
        assert_eq!(Expr::parse("f", "2*pi").unwrap().constant(), Some(2.0 * std::f64::consts::PI));
    }
}

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
    flat: FlatEx<f64>,
    /// For each of the expression's variables (in exmex's alphabetical order): 0 = x, 1 = y, 2 = t.
    slots: Vec<usize>,
    constant: Option<f64>,
}

impl Expr {
    /// Parse `text` (scene key `key`, used in messages).
    pub fn parse(key: &str, text: &str) -> Result<Self> {
        let err = |msg: String| Error::Expr {
            key: key.to_string(),
            expr: text.to_string(),
            msg,
        };
        if text.trim().is_empty() {
            return Err(err("empty expression".into()));
        }
        let flat = exmex::parse::<f64>(text).map_err(|e| err(format!("cannot parse: {e}")))?;
        let mut slots = Vec::new();
        for name in flat.var_names() {
            slots.push(match name.as_str() {
                "x" => 0,
                "y" => 1,
                "t" => 2,
                other => {
                    return Err(err(format!(
                        "unknown variable `{other}` (allowed: x, y, t)"
                    )))
                }
            });
        }
        let constant = if slots.is_empty() {
            let v = flat
                .eval(&[])
                .map_err(|e| err(format!("cannot evaluate: {e}")))?;
            if !v.is_finite() {
                return Err(err(format!("evaluates to {v}")));
            }
            Some(v)
        } else {
            None
        };
        Ok(Expr {
            key: key.to_string(),
            text: text.to_string(),
            flat,
            slots,
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
        self.slots.contains(&2)
    }

    /// The source text.
    pub fn text(&self) -> &str {
        &self.text
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
        let v = self
            .flat
            .eval(&vals[..self.slots.len()])
            .map_err(|e| Error::Expr {
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

/// A vector expression (two components).
#[derive(Clone, Debug)]
pub struct Vec2Expr(pub [Expr; 2]);

impl Vec2Expr {
    /// Parse two component strings; `key` names the scene entry.
    pub fn parse(key: &str, comps: &[String; 2]) -> Result<Self> {
        Ok(Vec2Expr([
            Expr::parse(&format!("{key}[0]"), &comps[0])?,
            Expr::parse(&format!("{key}[1]"), &comps[1])?,
        ]))
    }
    /// The zero vector.
    pub fn zero() -> Self {
        let z = Expr::parse("0", "0").expect("literal zero parses");
        Vec2Expr([z.clone(), z])
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
        assert!(
            e.contains("unknown variable `z`") && e.contains("loads.f[0]"),
            "{e}"
        );
    }

    #[test]
    fn non_finite_value_is_an_error() {
        let e = Expr::parse("g", "1/x").unwrap();
        assert!(e.eval(0.0, 0.0, 0.0).is_err());
        assert!(Expr::parse("g", "1/0").is_err());
    }

    #[test]
    fn constants_and_zero_detection() {
        assert!(Expr::parse("f", "0").unwrap().is_zero());
        assert!(!Expr::parse("f", "0*x").unwrap().is_zero());
        let pi = Expr::parse("f", "PI").unwrap().constant().unwrap();
        assert!((pi - std::f64::consts::PI).abs() < 1e-15);
    }
}

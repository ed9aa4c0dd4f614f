//! Boundary parts of a scene: what each named part of the boundary imposes, and Tresca's bound g_a.

use super::expr::{Expr, Vec2Expr};
use crate::error::{Error, Result};

/// What a boundary part imposes.
#[derive(Clone, Debug)]
pub enum PartKind {
    /// Clamped: u = 0.
    Dirichlet,
    /// Traction g(x, y, t); `None` is traction free (nothing assembled).
    Neumann(Option<Vec2Expr>),
    /// Bilateral contact u·n = 0 with Tresca bound g_a(x, y).
    Contact(FrictionBound),
}

/// Tresca's bound g_a(x, y) ≥ 0 of a contact part. It must not depend on t (checked when the scene is
/// read) and must not be negative, which [`FrictionBound::at`] checks wherever it is evaluated (a
/// constant bound is checked when the scene is read).
#[derive(Clone, Debug)]
pub struct FrictionBound(Expr);

impl FrictionBound {
    /// Parse the bound of scene key `key` in file `file`.
    pub fn parse(file: &str, key: &str, text: &str) -> Result<FrictionBound> {
        let g = FrictionBound(Expr::parse(key, text)?);
        if g.0.depends_on_t() {
            return Err(Error::scene(file, key, "the friction bound must not depend on t"));
        }
        if let Some(c) = g.0.constant() {
            if c < 0.0 {
                return Err(Error::scene(file, key, format!("must be >= 0, got {c}")));
            }
        }
        Ok(g)
    }

    /// g_a(x, y), refused with the point when negative.
    pub fn at(&self, x: f64, y: f64) -> Result<f64> {
        let v = self.0.eval(x, y, 0.0)?;
        if v < 0.0 {
            return Err(self.0.error(format!("negative friction bound {v:e} near ({x:.6}, {y:.6})")));
        }
        Ok(v)
    }

    /// The expression text.
    pub fn text(&self) -> &str {
        self.0.text()
    }
}

/// A named boundary part.
#[derive(Clone, Debug)]
pub struct Part {
    pub name: String,
    pub kind: PartKind,
}

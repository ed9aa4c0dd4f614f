//! Boundary parts of a scene: what each named part of the boundary imposes, Tresca's bound g_a and
//! the boundary data (keys `u` of a dirichlet part, `gap` of a contact part).
//!
//! **Boundary data.** A dirichlet part may give `u = ["…", "…"]`, u_D(x, y, t): it imposes u = u_D on
//! its edges as edge means (I_CR), and the stabilisation's jump on its edges is u_h − u_D. A contact
//! part may give `gap = "…"`, g_n(x, y, t): bilateral contact with imposed normal displacement
//! u·n = g_n (edge means), the tangential part under the same Tresca law. Both default to 0; an
//! expression that is the constant 0 counts as absent (the run is then that of the scene without it).
//! How the data enter the discrete problem: `fem::lifting`.

use super::expr::{Expr, Vec2Expr};
use super::values::sized;
use crate::error::{Error, Result};

/// What a boundary part imposes.
#[derive(Clone, Debug)]
pub enum PartKind {
    /// u = u_D(x, y, t) (as edge means); `None` is clamped, u = 0.
    Dirichlet(Option<Vec2Expr>),
    /// Traction g(x, y, t); `None` is traction free (nothing assembled).
    Neumann(Option<Vec2Expr>),
    /// Bilateral contact u·n = g_n(x, y, t) (`None`: g_n = 0) with Tresca bound g_a(x, y).
    Contact(FrictionBound, Option<Expr>),
}

impl PartKind {
    /// True for a dirichlet part (with or without data).
    pub fn is_dirichlet(&self) -> bool {
        matches!(self, PartKind::Dirichlet(_))
    }

    /// True if the part imposes nonzero boundary data (u_D or g_n).
    pub fn has_data(&self) -> bool {
        matches!(self, PartKind::Dirichlet(Some(_)) | PartKind::Contact(_, Some(_)))
    }
}

/// The Dirichlet data `u` of scene key `key` (None when absent or the constant 0).
pub(super) fn dirichlet_data(file: &str, key: &str, u: Option<&[String; 2]>) -> Result<Option<Vec2Expr>> {
    match u {
        None => Ok(None),
        Some(u) => Ok(Some(Vec2Expr::parse(key, sized(file, key, u)?)?).filter(|e| !e.is_zero())),
    }
}

/// The imposed normal displacement `gap` of scene key `key` (None when absent or the constant 0).
pub(super) fn gap_data(file: &str, key: &str, gap: Option<&String>) -> Result<Option<Expr>> {
    match gap {
        None => Ok(None),
        Some(g) => {
            sized::<1>(file, key, std::slice::from_ref(g).try_into().expect("one expression"))?;
            Ok(Some(Expr::parse(key, g)?).filter(|e| !e.is_zero()))
        }
    }
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

//! Boundary parts of a scene: what each named part of the boundary imposes, Tresca's bound g_a and
//! the boundary data (keys `u` of a dirichlet part, `gap` of a contact part).
//!
//! **Boundary data.** A dirichlet part may give `u = ["…", "…"]`, u_D(x, y, t): it imposes u = u_D on
//! its edges as edge means (I_CR), and the stabilisation's jump on its edges is u_h − u_D. A contact
//! part may give `gap = "…"`, g_n(x, y, t): bilateral contact with imposed normal displacement
//! u·n = g_n (edge means), the tangential part under the same Tresca law. Both default to 0; an
//! expression that is the constant 0 counts as absent (the run is then that of the scene without it).
//! How the data enter the discrete problem: `fem::lifting`.
//!
//! **Contact parts** ([`ContactPart`]) carry a law (bilateral u·n = g_n, or unilateral u·n ≤ g), a
//! friction law (Tresca's bound g_a, or Coulomb's coefficient F with the threshold F·p), an optional
//! surface load on Γ_C besides the contact reaction, and whether the scene gives normal unknowns to
//! every Γ_C edge ([`ContactPart::normal_unknown`]: with a unilateral or a Coulomb part). A `symmetry`
//! part is the frictionless bilateral contact part under another name (`symmetry` only changes what
//! `check` prints).

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
    /// Contact (or a symmetry part): see [`ContactPart`].
    Contact(Box<ContactPart>),
}

/// The normal law of a contact part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactLaw {
    /// u·n = g_n (edge means).
    Bilateral,
    /// u·n ≤ g, pressure p ≥ 0, p (u·n − g) = 0 (edge means).
    Unilateral,
}

/// The friction law of a contact part.
#[derive(Clone, Debug)]
pub enum FrictionLaw {
    /// Tresca: |σ_τ| ≤ g_a(x, y).
    Tresca(FrictionBound),
    /// Coulomb: |σ_τ| ≤ F(x, y) p (F read with the checks of a bound: ≥ 0, finite, independent of t).
    Coulomb(FrictionBound),
}

/// What a contact part imposes.
#[derive(Clone, Debug)]
pub struct ContactPart {
    pub law: ContactLaw,
    pub friction: FrictionLaw,
    /// g_n(x, y, t) (`None`: 0): imposed normal displacement (bilateral) or gap (unilateral).
    pub gap: Option<Expr>,
    /// A given surface load on Γ_C besides the contact reaction (`None`: none).
    pub traction: Option<Vec2Expr>,
    /// Written as `kind = "symmetry"` (frictionless bilateral, u·n = 0).
    pub symmetry: bool,
    /// True when the scene's Γ_C edges all carry a normal unknown (the scene has a unilateral or a
    /// Coulomb part): the normal condition is then solved with the friction, and a gap is not lifted.
    pub normal_unknown: bool,
}

impl ContactPart {
    /// The gap that is part of the lifting (`fem::lifting`): a bilateral gap without normal unknowns.
    pub fn lifted_gap(&self) -> Option<&Expr> {
        self.gap.as_ref().filter(|_| !self.normal_unknown)
    }

    /// What the part imposes, for `check` (`short` shortens an expression's text).
    pub fn describe(&self, short: impl Fn(&str) -> String) -> String {
        if self.symmetry {
            return "symmetry (u.n = 0, no friction)".to_string();
        }
        let gap = self.gap.as_ref().map_or("0".to_string(), |g| short(g.text()));
        let law = match self.law {
            ContactLaw::Bilateral => format!("contact u.n = {gap}"),
            ContactLaw::Unilateral => format!("unilateral contact u.n <= {gap}"),
        };
        let friction = match &self.friction {
            FrictionLaw::Tresca(g) => format!("Tresca g_a = {}", short(g.text())),
            FrictionLaw::Coulomb(f) => format!("Coulomb F = {}", short(f.text())),
        };
        match &self.traction {
            Some(g) => format!("{law}, {friction}, traction ({}, {})", short(g.0[0].text()), short(g.0[1].text())),
            None => format!("{law}, {friction}"),
        }
    }

    /// Tresca's bound g_a (None for Coulomb).
    pub fn tresca(&self) -> Option<&FrictionBound> {
        match &self.friction {
            FrictionLaw::Tresca(g) => Some(g),
            FrictionLaw::Coulomb(_) => None,
        }
    }

    /// Coulomb's coefficient F (None for Tresca).
    pub fn coulomb(&self) -> Option<&FrictionBound> {
        match &self.friction {
            FrictionLaw::Tresca(_) => None,
            FrictionLaw::Coulomb(f) => Some(f),
        }
    }
}

impl PartKind {
    /// True for a dirichlet part (with or without data).
    pub fn is_dirichlet(&self) -> bool {
        matches!(self, PartKind::Dirichlet(_))
    }

    /// True if the part imposes nonzero boundary data that the lifting carries (u_D, or a bilateral g_n
    /// without normal unknowns, [`ContactPart::lifted_gap`]).
    pub fn has_data(&self) -> bool {
        match self {
            PartKind::Dirichlet(u) => u.is_some(),
            PartKind::Contact(c) => c.lifted_gap().is_some(),
            PartKind::Neumann(_) => false,
        }
    }

    /// The contact part, if this is one.
    pub fn contact(&self) -> Option<&ContactPart> {
        match self {
            PartKind::Contact(c) => Some(c.as_ref()),
            _ => None,
        }
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

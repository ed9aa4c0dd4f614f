//! Boundary data that do not fit together are refused before anything is solved:
//!
//! * u₀ must equal u_D(·, t₀) on every Dirichlet edge (u_D = 0 where a part gives none),
//! * u₀·n must equal g_n(·, t₀) on every Γ_C edge (g_n = 0 where a part gives none),
//! * at a vertex shared by two Dirichlet parts their data must agree, and at a vertex shared by a
//!   Dirichlet and a contact part u_D·n_e = g_n (n_e the contact edge's normal), at every time node.
//!
//! Values are compared at the 3-point Gauss points of the edges (u₀ and the data) and at the shared
//! vertices. Tolerance: the largest of
//! * 1e-9 of the size of the data (the largest |u₀| at a mesh vertex or value compared: a real mismatch
//!   below that is far below what the discretisation resolves);
//! * [`ROUNDING_ULPS`] ulps of the size the data reach over the whole time grid (the largest |u_D|, |g_n|
//!   at the vertices of the parts with data, at every time node): data that vanish at t₀ and grow later;
//! * [`ROUNDING_SAFETY`] times the rounding error bound of the two values compared
//!   (`scene::expr::rounding`: each expression's literals and operations, and the dot product with the
//!   normal). It is what admits data that cancel to zero at t₀ by rounding whatever they do later:
//!   `gap = "(0.1 + t)^2 - 0.01 - 0.2*t - t^2"` is 1.7e-18 at t₀ = 0, within its bound (of order 1e-17) of the
//!   u₀·n = 0 it is compared with, and is accepted, while `gap = "1e-17"` is refused (below, and the
//!   test `data_cancelling_by_rounding_are_accepted` of tests/hostile/validation.rs):
//!
//! ```
//! use tresca_cr::{fem::lifting::consistency::check, fem::space::CrSpace, mesh::Mesh, Scene};
//! let text = r#"
//!     mesh = { corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], cells = [2, 2] }
//!     material = { E = 10.0, nu = 0.3 }
//!     time = { T = 1.0, steps = 2 }
//!     [[boundary]]
//!     name = "top"
//!     kind = "dirichlet"
//!     [[boundary]]
//!     name = "left"
//!     kind = "neumann"
//!     [[boundary]]
//!     name = "right"
//!     kind = "neumann"
//!     [[boundary]]
//!     name = "bottom"
//!     kind = "contact"
//!     g_a = "0.1"
//!     gap = "GAP""#;
//! let checked = |gap: &str| -> tresca_cr::Result<()> {
//!     let scene = Scene::from_str(&text.replace("GAP", gap), "doc.toml")?;
//!     let mesh = Mesh::from_spec(&scene.mesh)?;
//!     check(&scene, &mesh, &CrSpace::new(&mesh, &scene.parts)?)
//! };
//! checked("(0.1 + t)^2 - 0.01 - 0.2*t - t^2")?; // 1.7e-18 at t₀ = 0: rounding, accepted
//! assert!(checked("1e-17").is_err()); // a mismatch with u₀·n = 0, refused
//! # Ok::<(), tresca_cr::Error>(())
//! ```
//!
//! Only scenes with boundary data are checked: without them (u_D = 0, g_n = 0) a u₀ that does not vanish
//! on Γ_D or whose normal part does not vanish on Γ_C is projected onto V_h (those values dropped), as
//! in every earlier version, so that such scenes run unchanged.

use super::gauss3_points;
use crate::error::{Error, Result};
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::expr::Vec2Expr;
use crate::scene::{PartKind, Scene};

/// Ulps of the data's size over time that rounding of an expression may leave where its terms cancel
/// (module doc): one ulp per operation for expressions of a few dozen operations.
pub const ROUNDING_ULPS: f64 = 64.0;

/// The factor on the rounding bound of the values compared (module doc): the bound is to first order in
/// the unit roundoff and is taken along the expression tree, while the values come from the compiled
/// program, whose grouping and folding differ (an error of the same order); twice the bound covers both.
pub const ROUNDING_SAFETY: f64 = 2.0;

/// A mismatch found: (what, where, the two values, the rounding bound of their difference).
type Mismatch = (String, [f64; 2], f64, f64, f64);

/// The rounding bound of u·n from the components' bounds `r`: theirs times |n|, plus the two products'
/// and the sum's roundings, each within the unit roundoff of |u₀n₀| + |u₁n₁|.
fn dot_rounding(u: [f64; 2], r: [f64; 2], n: [f64; 2]) -> f64 {
    let terms = (u[0] * n[0]).abs() + (u[1] * n[1]).abs();
    r[0] * n[0].abs() + r[1] * n[1].abs() + 1.5 * f64::EPSILON * terms
}

/// The rounding bounds of u₀, u_D (zero where absent) at (x, y, t).
fn vec_rounding(u: &Option<Vec2Expr>, x: [f64; 2], t: f64) -> [f64; 2] {
    u.as_ref().map_or([0.0; 2], |u| u.rounding(x[0], x[1], t))
}

fn gap_rounding(g: &Option<crate::scene::expr::Expr>, x: [f64; 2], t: f64) -> f64 {
    g.as_ref().map_or(0.0, |g| g.rounding(x[0], x[1], t))
}

/// Refuse inconsistent boundary data (module doc), naming the parts, the point and the values.
pub fn check(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<()> {
    if !scene.has_boundary_data() {
        return Ok(());
    }
    let mut cmp: Vec<Mismatch> = Vec::new();
    let t0 = scene.times[0];
    let zero = |_: f64, _: f64, _: f64| Ok([0.0, 0.0]);
    let u0 = |x: f64, y: f64| match &scene.u0 {
        Some(u) => u.eval(x, y, t0),
        None => zero(x, y, t0),
    };
    let ud = |u: &Option<Vec2Expr>, x: f64, y: f64, t: f64| match u {
        Some(u) => u.eval(x, y, t),
        None => zero(x, y, t),
    };
    for e in 0..mesh.edges.len() {
        let Some(p) = space.edge_part[e] else { continue };
        let part = &scene.parts[p];
        match &part.kind {
            PartKind::Dirichlet(u) => {
                if u.is_none() && scene.u0.is_none() {
                    continue;
                }
                for x in gauss3_points(mesh, e) {
                    let (a, b) = (u0(x[0], x[1])?, ud(u, x[0], x[1], t0)?);
                    let (ra, rb) = (vec_rounding(&scene.u0, x, t0), vec_rounding(u, x, t0));
                    for c in 0..2 {
                        cmp.push((
                            format!("initial.u0[{c}] and part `{}`'s u[{c}] at t0 = {t0}", part.name),
                            x,
                            a[c],
                            b[c],
                            ra[c] + rb[c],
                        ));
                    }
                }
            }
            PartKind::Contact(c) => {
                // with normal unknowns the gap is not lifted: a unilateral initial state is checked for
                // penetration instead (`fem::gap`)
                if c.normal_unknown {
                    continue;
                }
                let g = &c.gap;
                if g.is_none() && scene.u0.is_none() {
                    continue;
                }
                let n = mesh.outward_normal(e);
                for x in gauss3_points(mesh, e) {
                    let a = u0(x[0], x[1])?;
                    let b = match g {
                        Some(g) => g.eval(x[0], x[1], t0)?,
                        None => 0.0,
                    };
                    let r = dot_rounding(a, vec_rounding(&scene.u0, x, t0), n) + gap_rounding(g, x, t0);
                    cmp.push((
                        format!("initial.u0·n and part `{}`'s gap at t0 = {t0}", part.name),
                        x,
                        a[0] * n[0] + a[1] * n[1],
                        b,
                        r,
                    ));
                }
            }
            PartKind::Neumann(_) => {}
        }
    }
    shared_vertices(scene, mesh, space, &mut cmp)?;
    let mut scale = cmp.iter().fold(0.0f64, |m, c| m.max(c.2.abs()).max(c.3.abs()));
    for x in &mesh.points {
        let v = u0(x[0], x[1])?;
        scale = scale.max(v[0].abs()).max(v[1].abs());
    }
    let tol = (1e-9 * scale).max(ROUNDING_ULPS * f64::EPSILON * data_size(scene, mesh, space)?);
    let allowed = |r: f64| tol.max(ROUNDING_SAFETY * r);
    match cmp.into_iter().find(|c| (c.2 - c.3).abs() > allowed(c.4)) {
        None => Ok(()),
        Some((what, x, a, b, r)) => Err(Error::scene(
            &scene.file,
            "boundary",
            format!(
                "inconsistent boundary data: {what} differ at ({:.6}, {:.6}): {a:e} against {b:e} (tolerance {:.1e})",
                x[0],
                x[1],
                allowed(r)
            ),
        )),
    }
}

/// The comparisons at vertices shared by parts with data (module doc), at every time node.
fn shared_vertices(scene: &Scene, mesh: &Mesh, space: &CrSpace, cmp: &mut Vec<Mismatch>) -> Result<()> {
    // per vertex: the boundary edges at it with their parts
    let mut at: Vec<Vec<(usize, usize)>> = vec![Vec::new(); mesh.points.len()];
    for e in 0..mesh.edges.len() {
        if let Some(p) = space.edge_part[e] {
            for v in mesh.edges[e] {
                at[v].push((e, p));
            }
        }
    }
    for (v, edges) in at.iter().enumerate() {
        let x = mesh.points[v];
        for (i, &(ea, pa)) in edges.iter().enumerate() {
            for &(eb, pb) in &edges[i + 1..] {
                if pa == pb {
                    continue;
                }
                let (a, b) = (&scene.parts[pa], &scene.parts[pb]);
                if !a.kind.has_data() && !b.kind.has_data() {
                    continue;
                }
                let what = format!("parts `{}` and `{}` at their common vertex", a.name, b.name);
                for &t in &scene.times {
                    match (&a.kind, &b.kind) {
                        (PartKind::Dirichlet(ua), PartKind::Dirichlet(ub)) => {
                            let (va, vb) = (vec_at(ua, x, t)?, vec_at(ub, x, t)?);
                            let (ra, rb) = (vec_rounding(ua, x, t), vec_rounding(ub, x, t));
                            for c in 0..2 {
                                cmp.push((format!("{what} (u[{c}], t = {t})"), x, va[c], vb[c], ra[c] + rb[c]));
                            }
                        }
                        (PartKind::Dirichlet(u), PartKind::Contact(c)) if !c.normal_unknown => {
                            let g = &c.gap;
                            let (un, r) = normal_of(mesh, eb, u, x, t)?;
                            let what = format!("{what} (u·n against gap, t = {t})");
                            cmp.push((what, x, un, gap_at(g, x, t)?, r + gap_rounding(g, x, t)));
                        }
                        (PartKind::Contact(c), PartKind::Dirichlet(u)) if !c.normal_unknown => {
                            let g = &c.gap;
                            let (un, r) = normal_of(mesh, ea, u, x, t)?;
                            let what = format!("{what} (gap against u·n, t = {t})");
                            cmp.push((what, x, gap_at(g, x, t)?, un, r + gap_rounding(g, x, t)));
                        }
                        _ => {}
                    }
                }
            }
        }
    }
    Ok(())
}

/// The largest |u_D| component and |g_n| at the vertices of the parts with data, over every time node
/// (a value that cannot be evaluated or is not finite is skipped: the run names it at its step).
fn data_size(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Result<f64> {
    let mut size = 0.0f64;
    for (e, p) in space.edge_part.iter().enumerate() {
        let Some(kind) = p.map(|p| &scene.parts[p].kind) else { continue };
        for x in mesh.edges[e].map(|v| mesh.points[v]) {
            for &t in &scene.times {
                let v = match kind {
                    PartKind::Dirichlet(u @ Some(_)) => vec_at(u, x, t).unwrap_or([0.0; 2]),
                    PartKind::Contact(c) if c.lifted_gap().is_some() => [gap_at(&c.gap, x, t).unwrap_or(0.0), 0.0],
                    _ => break,
                };
                size = v.iter().filter(|c| c.is_finite()).fold(size, |m, c| m.max(c.abs()));
            }
        }
    }
    Ok(size)
}

fn vec_at(u: &Option<Vec2Expr>, x: [f64; 2], t: f64) -> Result<[f64; 2]> {
    u.as_ref().map_or(Ok([0.0; 2]), |u| u.eval(x[0], x[1], t))
}

fn gap_at(g: &Option<crate::scene::expr::Expr>, x: [f64; 2], t: f64) -> Result<f64> {
    g.as_ref().map_or(Ok(0.0), |g| g.eval(x[0], x[1], t))
}

/// u_D·n_e at (x, t) for the outward normal of edge e, with its rounding bound.
fn normal_of(mesh: &Mesh, e: usize, u: &Option<Vec2Expr>, x: [f64; 2], t: f64) -> Result<(f64, f64)> {
    let (n, v) = (mesh.outward_normal(e), vec_at(u, x, t)?);
    Ok((v[0] * n[0] + v[1] * n[1], dot_rounding(v, vec_rounding(u, x, t), n)))
}

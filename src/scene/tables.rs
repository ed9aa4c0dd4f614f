//! The tables of a scene file read and checked one by one ([`super::Scene::from_str`] puts them
//! together): each function takes its raw serde table and returns the validated value, or an error
//! naming the key.

use super::expr::{Expr, Vec2Expr};
use super::raw::*;
use super::values::{positive_finite, sized, uniform_times};
use super::SolverSettings;
use super::{
    ContactLaw, ContactPart, Diagonal, Exact, FrictionBound, FrictionLaw, MeshSpec, Method, Outputs, Part, PartKind,
};
use crate::error::{Error, Result};

/// `[mesh]`: a Gmsh file or a structured quadrilateral, with its refinements.
pub(super) fn mesh_spec(file: &str, m: &RawMeshTable) -> Result<MeshSpec> {
    let spec = match (&m.file, m.corners, m.cells) {
        (Some(p), None, None) => {
            if m.diagonal.is_some() {
                return Err(Error::scene(file, "mesh.diagonal", "only for structured meshes"));
            }
            MeshSpec::Gmsh { path: p.clone(), refine: m.refine }
        }
        (None, Some(corners), Some(cells)) => {
            if cells[0] == 0 || cells[1] == 0 {
                return Err(Error::scene(file, "mesh.cells", "cell counts must be at least 1"));
            }
            if corners.iter().flatten().any(|c| !c.is_finite()) {
                return Err(Error::scene(file, "mesh.corners", "corners must be finite"));
            }
            let diagonal = m.diagonal.unwrap_or(Diagonal::First);
            MeshSpec::Structured { corners, cells, diagonal, refine: m.refine }
        }
        _ => {
            return Err(Error::scene(
                file,
                "mesh",
                "give either `file` (Gmsh) or both `corners` and `cells` (structured), not both",
            ))
        }
    };
    check_refine(file, "mesh.refine", m.refine)?;
    Ok(spec)
}

/// `[material]`: E > 0 and −1 < ν < ½ (plane strain).
pub(super) fn material(file: &str, m: &RawMaterial) -> Result<(f64, f64)> {
    let e = positive_finite(file, "material.E", m.E)?;
    let nu = m.nu;
    if !(nu.is_finite() && nu > -1.0 && nu < 0.5) {
        return Err(Error::scene(file, "material.nu", format!("must satisfy -1 < nu < 0.5, got {nu}")));
    }
    Ok((e, nu))
}

/// `[[boundary]]`: the parts, named once each, with the data of their kind; at least one Dirichlet part.
pub(super) fn parts(file: &str, boundary: &[RawBoundary]) -> Result<Vec<Part>> {
    let mut parts = Vec::new();
    for (i, b) in boundary.iter().enumerate() {
        let key = |k: &str| format!("boundary[{i}] ({}).{k}", b.name);
        if parts.iter().any(|p: &Part| p.name == b.name) {
            return Err(Error::scene(file, key("name"), "boundary part named twice"));
        }
        refuse_foreign_keys(file, b, &key)?;
        let kind = match b.kind {
            RawKind::Dirichlet => PartKind::Dirichlet(super::parts::dirichlet_data(file, &key("u"), b.u.as_ref())?),
            RawKind::Neumann => PartKind::Neumann(traction(file, &key("traction"), b.traction.as_ref())?),
            RawKind::Contact => PartKind::Contact(Box::new(contact_part(file, b, &key)?)),
            RawKind::Symmetry => PartKind::Contact(Box::new(ContactPart {
                law: ContactLaw::Bilateral,
                friction: FrictionLaw::Tresca(FrictionBound::parse(file, &key("kind"), "0")?),
                gap: None,
                traction: None,
                symmetry: true,
                normal_unknown: false,
            })),
        };
        parts.push(Part { name: b.name.clone(), kind });
    }
    let normal =
        parts.iter().filter_map(|p| p.kind.contact()).any(|c| c.law == ContactLaw::Unilateral || c.coulomb().is_some());
    for p in &mut parts {
        if let PartKind::Contact(c) = &mut p.kind {
            c.normal_unknown = normal;
        }
    }
    // a body held only by contact and symmetry parts floats: its rigid motions are balanced by the contact
    // forces (`solve::kernel`, `friction::floating`)
    if !parts.iter().any(|p| p.kind.is_dirichlet() || p.kind.contact().is_some()) {
        return Err(Error::scene(
            file,
            "boundary",
            "no dirichlet part: rigid motions are not fixed (the paper requires meas(Γ_D) > 0)",
        ));
    }
    Ok(parts)
}

/// The keys a part's kind does not take, refused naming the part.
fn refuse_foreign_keys(file: &str, b: &RawBoundary, key: &dyn Fn(&str) -> String) -> Result<()> {
    let contact = b.kind == RawKind::Contact;
    let given = [
        (
            "traction",
            b.traction.is_some(),
            matches!(b.kind, RawKind::Neumann | RawKind::Contact),
            "neumann and contact parts take a traction",
        ),
        ("g_a", b.g_a.is_some(), contact, "contact parts take a friction bound g_a"),
        ("u", b.u.is_some(), b.kind == RawKind::Dirichlet, "dirichlet parts take boundary values u"),
        ("gap", b.gap.is_some(), contact, "contact parts take a gap"),
        ("law", b.law.is_some(), contact, "contact parts take a contact law"),
        ("coulomb", b.coulomb.is_some(), contact, "contact parts take a Coulomb coefficient"),
    ];
    for (k, present, allowed, what) in given {
        if present && !allowed {
            let msg = if b.kind == RawKind::Symmetry {
                "a symmetry part takes no keys besides name and kind (u·n = 0, no friction)".to_string()
            } else {
                format!("only {what}")
            };
            return Err(Error::scene(file, key(k), msg));
        }
    }
    Ok(())
}

/// A traction of scene key `key` (`None` where absent or zero).
fn traction(file: &str, key: &str, g: Option<&[String; 2]>) -> Result<Option<Vec2Expr>> {
    match g {
        Some(g) => Ok(nonzero(Some(Vec2Expr::parse(key, sized(file, key, g)?)?))),
        None => Ok(None),
    }
}

/// A `kind = "contact"` part: law, friction (`g_a` or `coulomb`, not both), gap and traction.
fn contact_part(file: &str, b: &RawBoundary, key: &dyn Fn(&str) -> String) -> Result<ContactPart> {
    let law = match b.law.as_deref() {
        None | Some("bilateral") => ContactLaw::Bilateral,
        Some("unilateral") => ContactLaw::Unilateral,
        Some(other) => {
            return Err(Error::scene(
                file,
                key("law"),
                format!("unknown contact law `{other}` (expected \"bilateral\" or \"unilateral\")"),
            ))
        }
    };
    let friction = match (&b.g_a, &b.coulomb) {
        (Some(_), Some(_)) => {
            return Err(Error::scene(file, key("coulomb"), "give either g_a (Tresca) or coulomb (Coulomb), not both"))
        }
        (None, None) => return Err(Error::scene(file, key("g_a"), "contact part needs g_a (Tresca) or coulomb")),
        (Some(g), None) => {
            sized(file, &key("g_a"), std::array::from_ref(g))?;
            FrictionLaw::Tresca(FrictionBound::parse(file, &key("g_a"), g)?)
        }
        (None, Some(f)) => {
            sized(file, &key("coulomb"), std::array::from_ref(f))?;
            FrictionLaw::Coulomb(FrictionBound::parse(file, &key("coulomb"), f)?)
        }
    };
    Ok(ContactPart {
        law,
        friction,
        gap: super::parts::gap_data(file, &key("gap"), b.gap.as_ref())?,
        traction: traction(file, &key("traction"), b.traction.as_ref())?,
        symmetry: false,
        normal_unknown: false,
    })
}

/// `[loads] f` and `[initial] u0` (independent of t); `None` where absent or zero.
pub(super) fn loads(
    file: &str,
    loads: Option<RawLoads>,
    initial: Option<RawInitial>,
) -> Result<(Option<Vec2Expr>, Option<Vec2Expr>)> {
    let f = match loads.and_then(|l| l.f) {
        Some(f) => nonzero(Some(Vec2Expr::parse("loads.f", sized(file, "loads.f", &f)?)?)),
        None => None,
    };
    let u0 = match initial.and_then(|l| l.u0) {
        Some(u) => {
            let u = Vec2Expr::parse("initial.u0", sized(file, "initial.u0", &u)?)?;
            if u.depends_on_t() {
                return Err(Error::scene(file, "initial.u0", "must not depend on t"));
            }
            nonzero(Some(u))
        }
        None => None,
    };
    Ok((f, u0))
}

/// `[time]`: the nodes, and whether they are uniform (from `T` and `steps`).
pub(super) fn time_grid(file: &str, t: RawTime) -> Result<(Vec<f64>, bool)> {
    match (t.T, t.steps, t.times) {
        (Some(t), Some(n), None) => {
            let t = positive_finite(file, "time.T", t)?;
            Ok((uniform_times(file, t, n)?, true))
        }
        (None, None, Some(ts)) => {
            if ts.len() < 2 {
                return Err(Error::scene(file, "time.times", "needs at least two time nodes"));
            }
            for (k, w) in ts.windows(2).enumerate() {
                if !(w[0].is_finite() && w[1].is_finite() && w[1] > w[0]) {
                    return Err(Error::scene(
                        file,
                        "time.times",
                        format!(
                            "must be finite and strictly increasing: times[{k}] = {}, times[{}] = {}",
                            w[0],
                            k + 1,
                            w[1]
                        ),
                    ));
                }
            }
            Ok((ts, false))
        }
        _ => Err(Error::scene(file, "time", "give either `T` and `steps`, or `times`")),
    }
}

/// `[solver]`, with its defaults (SSN, tolerance 1e-12, the method's iteration limit, automatic Uzawa step).
pub(super) fn solver_settings(file: &str, raw: Option<RawSolver>) -> Result<SolverSettings> {
    let rs = raw.unwrap_or(RawSolver { method: None, tol: None, max_iter: None, uzawa_step: None });
    Ok(SolverSettings {
        method: rs.method.unwrap_or(Method::Ssn),
        tol: positive_finite(file, "solver.tol", rs.tol.unwrap_or(1e-12))?,
        max_iter_given: match rs.max_iter {
            Some(0) => return Err(Error::scene(file, "solver.max_iter", "must be at least 1")),
            other => other,
        },
        uzawa_step: match rs.uzawa_step {
            Some(s) if !(s.is_finite() && s >= 0.0) => {
                return Err(Error::scene(file, "solver.uzawa_step", format!("must be >= 0 (0 = automatic), got {s}")))
            }
            Some(s) => s,
            None => 0.0,
        },
    })
}

/// `[exact]`: u and its gradient, for true errors.
pub(super) fn exact(file: &str, raw: Option<RawExact>) -> Result<Option<Exact>> {
    let Some(x) = raw else { return Ok(None) };
    sized(file, "exact.u", &x.u)?;
    for row in &x.grad {
        sized(file, "exact.grad", row)?;
    }
    let g = |i: usize, j: usize| Expr::parse(&format!("exact.grad[{i}][{j}]"), &x.grad[i][j]);
    Ok(Some(Exact { u: Vec2Expr::parse("exact.u", &x.u)?, grad: [[g(0, 0)?, g(0, 1)?], [g(1, 0)?, g(1, 1)?]] }))
}

/// `[quantities]`, or the deprecated `[outputs]` (a message in `deprecations`), with `energy` read as
/// `elastic_energy` (likewise).
pub(super) fn quantities(
    file: &str,
    new: Option<RawQuantities>,
    old: Option<RawQuantities>,
    deprecations: &mut Vec<String>,
) -> Result<Option<Outputs>> {
    let raw = match (new, old) {
        (Some(_), Some(_)) => {
            return Err(Error::scene(file, "outputs", "give [quantities] only (`[outputs]` is its deprecated name)"))
        }
        (None, Some(o)) => {
            deprecations.push(format!("{file}: the table [outputs] is deprecated: write [quantities]"));
            o
        }
        (Some(q), None) => q,
        (None, None) => return Ok(None),
    };
    let elastic_energy = match (raw.elastic_energy, raw.energy) {
        (Some(_), Some(_)) => {
            return Err(Error::scene(
                file,
                "quantities.energy",
                "give elastic_energy only (`energy` is its deprecated name)",
            ))
        }
        (None, Some(e)) => {
            deprecations
                .push(format!("{file}: [quantities] energy is deprecated: write elastic_energy (½ a_h(u, u) at T)"));
            e
        }
        (e, None) => e.unwrap_or(false),
    };
    Ok(Some(Outputs {
        max_slip: raw.max_slip,
        stick_length: raw.stick_length,
        elastic_energy,
        traction_at: raw.traction_at,
    }))
}

/// Uniform refinements beyond [`MAX_REFINE`] are refused (4¹² times the triangles is beyond any machine).
pub(super) fn check_refine(file: &str, key: &str, k: u32) -> Result<()> {
    if k > MAX_REFINE {
        return Err(Error::scene(file, key, format!("{k} refinements is beyond any machine")));
    }
    Ok(())
}

/// The most uniform refinements a scene or `--refine` may ask for.
pub const MAX_REFINE: u32 = 12;

pub(super) fn nonzero(v: Option<Vec2Expr>) -> Option<Vec2Expr> {
    v.filter(|e| !e.is_zero())
}

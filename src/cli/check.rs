//! `tresca-cr check`: validate a scene, set it up, and print what it will model. A level too large to set
//! up quickly ([`ASSEMBLED_UNKNOWNS`]) is not assembled: the scene is set up (and so validated) at the
//! finest coarser level that is, and the counts of the asked level follow exactly from it, since each
//! red refinement maps T triangles, E edges and V vertices to 4T, 2E + 3T and V + E, and doubles the
//! edges of every boundary part.

use super::out::say;
use anyhow::Result;
use tresca_cr::output::guard::Outputs;
use tresca_cr::scene::budget::Estimate;
use tresca_cr::scene::PartKind;
use tresca_cr::{Problem, Scene};

/// Largest estimated number of unknowns `check` assembles and factors (about a second on one core); a
/// finer level is counted from the finest coarser one within it.
const ASSEMBLED_UNKNOWNS: u64 = 100_000;

/// An expression for display: long generated expressions are shortened.
fn short(text: &str) -> String {
    if text.chars().count() <= 48 {
        text.to_string()
    } else {
        format!("{}… ({} characters)", text.chars().take(40).collect::<String>(), text.chars().count())
    }
}

/// The finest level ≤ the scene's whose estimate is within [`ASSEMBLED_UNKNOWNS`], and the scene at it.
fn assembled_level(scene: &Scene) -> Result<(u32, Scene)> {
    let mut s = scene.clone();
    let mut r = scene.mesh_level();
    while r > 0 && Estimate::of(&s, 1, false)?.unknowns > ASSEMBLED_UNKNOWNS {
        r -= 1;
        s.set_refine(r)?;
    }
    Ok((r, s))
}

/// Vertices, triangles and edges after `k` red refinements of a mesh with `v`, `t`, `e`.
fn refined(mut v: u64, mut t: u64, mut e: u64, k: u32) -> (u64, u64, u64) {
    for _ in 0..k {
        (v, t, e) = (v.saturating_add(e), t.saturating_mul(4), e.saturating_mul(2).saturating_add(t.saturating_mul(3)));
    }
    (v, t, e)
}

/// The counts of the asked level, from the level set up and the `k` red refinements beyond it (exact: the
/// module doc), for the human lines and `--json` alike.
struct Counts {
    vertices: u64,
    triangles: u64,
    edges: u64,
    h: f64,
    unknowns: u64,
    paper_dofs: u64,
    contact_unknowns: u64,
}

impl Counts {
    fn of(problem: &Problem, s: &Scene, k: u32) -> Counts {
        let (m, sp) = (&problem.mesh, &problem.space);
        let (vertices, triangles, edges) = refined(m.points.len() as u64, m.tris.len() as u64, m.edges.len() as u64, k);
        // boundary edges double with each refinement
        let (dirichlet, contact) = ((sp.n_dirichlet as u64) << k, (sp.contact.len() as u64) << k);
        // two unknowns per free edge, one per contact edge (two with normal unknowns), none on Dirichlet edges
        let paper_dofs = edges.saturating_sub(dirichlet).saturating_mul(2);
        let (unknowns, contact_unknowns) = if s.has_normal_unknowns() {
            (paper_dofs, 2 * contact)
        } else {
            (paper_dofs.saturating_sub(contact), contact)
        };
        Counts {
            vertices,
            triangles,
            edges,
            h: m.h_max() / f64::from(1u32 << k),
            unknowns,
            paper_dofs,
            contact_unknowns,
        }
    }
}

pub fn check(scene: Scene, estimate: Estimate, reports: super::summary::Reports) -> Result<()> {
    let start = std::time::Instant::now();
    let (json, force) = (reports.json, reports.force);
    Outputs::new(force).inputs_of(&scene).files(json.as_deref(), "--json file").check()?;
    let level = scene.mesh_level();
    let (at, built) = assembled_level(&scene)?;
    let k = level - at;
    let problem = Problem::new(built)?;
    // what `run` evaluates before its first step: u⁰ = I_CR u₀ and, with [exact], the errors at t₀
    problem.initial()?;
    let (s, sp) = (&scene, &problem.space);
    let c = Counts::of(&problem, s, k);
    say!("scene      {} ({})", s.file, if s.title.is_empty() { "untitled" } else { &s.title });
    say!("mesh       {} vertices, {} triangles, {} edges, h = {:.4e}", c.vertices, c.triangles, c.edges, c.h);
    if k > 0 {
        say!(
            "           (refine {level} is counted, not assembled: the scene was set up at refine {at}, and each of \
             the {k} red refinements beyond it maps T, E, V to 4T, 2E + 3T, V + E)"
        );
    }
    say!(
        "material   E = {}, nu = {} (plane strain: lambda = {:.6e}, mu = {:.6e})",
        s.material.e,
        s.material.nu,
        problem.law.lam,
        problem.law.mu
    );
    for (p, part) in s.parts.iter().enumerate() {
        let n = (sp.edge_part.iter().filter(|&&q| q == Some(p)).count() as u64) << k;
        say!("part       {:<10} {:>6} edges  {}", part.name, n, describe(&part.kind));
    }
    if let Some(kernel) = problem.free.kernel() {
        say!(
            "floating   no dirichlet part: {} free before contact, held only by contact and friction (their \
             equilibrium is solved exactly at every step; a step whose loads they cannot balance is refused)",
            kernel.motions.names().join(", ")
        );
    }
    say!(
        "unknowns   {} (paper's count 2(edges - Dirichlet edges) = {}), {} contact unknowns",
        c.unknowns,
        c.paper_dofs,
        c.contact_unknowns
    );
    say!("assembled  {}", assembled_terms(s));
    say!(
        "time       {} steps on [{}, {}]{}",
        s.times.len() - 1,
        s.times[0],
        s.times.last().unwrap_or(&0.0),
        if s.uniform_time { " (uniform)" } else { "" }
    );
    say!("solver     {} (tol {:.1e}, max_iter {})", s.solver.method.name(), s.solver.tol, s.solver.max_iter());
    say!("exact      {}", if s.exact.is_some() { "given: true errors computed" } else { "none" });
    say!("estimate   {}", estimate.describe());
    let points = tresca_cr::fem::singular::singularities(&problem.mesh, &sp.edge_part, &s.parts, s.material.nu);
    let (lines, singular) = super::corners::describe(&points, &s.parts);
    lines.iter().for_each(|l| say!("{l}"));
    if let Some(j) = &json {
        write_json(j, (&problem, &c), s, &estimate, singular, (start.elapsed().as_secs_f64(), force))?;
    }
    match super::out::stdout_error() {
        Some(e) => anyhow::bail!("cannot write to standard output: {e}"),
        None => Ok(()),
    }
}

/// What a boundary part imposes, for the `part` lines.
fn describe(kind: &PartKind) -> String {
    match kind {
        PartKind::Dirichlet(None) => "dirichlet (u = 0)".to_string(),
        PartKind::Dirichlet(Some(u)) => {
            format!("dirichlet, u_D = ({}, {})", short(u.0[0].text()), short(u.0[1].text()))
        }
        PartKind::Neumann(None) => "neumann, traction free (nothing assembled)".to_string(),
        PartKind::Neumann(Some(g)) => format!("neumann, g = ({}, {})", short(g.0[0].text()), short(g.0[1].text())),
        PartKind::Contact(c) => c.describe(short),
    }
}

/// The terms the scene assembles, for the `assembled` line.
fn assembled_terms(s: &Scene) -> String {
    let stab = format!("jump stabilisation (rho = {})", s.rho);
    let mut terms = vec!["elastic stiffness", stab.as_str()];
    if s.f.is_some() {
        terms.push("body force");
    }
    if s.parts.iter().any(|p| matches!(p.kind, PartKind::Neumann(Some(_)))) {
        terms.push("Neumann traction");
    }
    if s.has_contact() {
        terms.push("Tresca friction (condensed on contact unknowns)");
    } else {
        terms.push("no contact: plain elasticity");
    }
    terms.join(", ")
}

/// The JSON summary of `check` (the asked level's counts, [`Counts`]) to `j`.
fn write_json(
    j: &std::path::Path,
    (problem, c): (&Problem, &Counts),
    s: &Scene,
    estimate: &Estimate,
    singular: super::summary::Singular,
    (wall, force): (f64, bool),
) -> Result<()> {
    let count = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
    let mut summary = super::summary::Summary::new("check", &s.file, wall);
    summary.check = Some(super::summary::CheckSummary {
        vertices: count(c.vertices),
        triangles: count(c.triangles),
        edges: count(c.edges),
        h: c.h,
        unknowns: count(c.unknowns),
        paper_dofs: count(c.paper_dofs),
        contact_unknowns: count(c.contact_unknowns),
        steps: problem.n_steps(),
        solver: s.solver.method.name().into(),
        tol: s.solver.tol,
        max_iter: s.solver.max_iter(),
        exact: s.exact.is_some(),
        setup: problem.setup.into(),
        memory: estimate.memory,
        disk: estimate.disk,
        singular,
    });
    super::summary::write(j, &summary, force)?;
    Ok(())
}

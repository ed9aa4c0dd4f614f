//! `tresca-cr check`: validate a scene, set it up, and print what it will model.

use super::out::say;
use anyhow::Result;
use tresca_cr::scene::budget::Estimate;
use tresca_cr::scene::PartKind;
use tresca_cr::{Problem, Scene};

/// An expression for display: long generated expressions are shortened.
fn short(text: &str) -> String {
    if text.chars().count() <= 48 {
        text.to_string()
    } else {
        format!("{}… ({} characters)", text.chars().take(40).collect::<String>(), text.chars().count())
    }
}

pub fn check(scene: Scene, estimate: Estimate, json: Option<std::path::PathBuf>) -> Result<()> {
    let start = std::time::Instant::now();
    let problem = Problem::new(scene)?;
    // what `run` evaluates before its first step: u⁰ = I_CR u₀ and, with [exact], the errors at t₀
    problem.initial()?;
    let (s, m, sp) = (&problem.scene, &problem.mesh, &problem.space);
    say!("scene      {} ({})", s.file, if s.title.is_empty() { "untitled" } else { &s.title });
    say!(
        "mesh       {} vertices, {} triangles, {} edges, h = {:.4e}",
        m.points.len(),
        m.tris.len(),
        m.edges.len(),
        m.h_max()
    );
    say!(
        "material   E = {}, nu = {} (plane strain: lambda = {:.6e}, mu = {:.6e})",
        s.material.e,
        s.material.nu,
        problem.law.lam,
        problem.law.mu
    );
    for (p, part) in s.parts.iter().enumerate() {
        let n = sp.edge_part.iter().filter(|&&q| q == Some(p)).count();
        let what = match &part.kind {
            PartKind::Dirichlet(None) => "dirichlet (u = 0)".to_string(),
            PartKind::Dirichlet(Some(u)) => {
                format!("dirichlet, u_D = ({}, {})", short(u.0[0].text()), short(u.0[1].text()))
            }
            PartKind::Neumann(None) => "neumann, traction free (nothing assembled)".to_string(),
            PartKind::Neumann(Some(g)) => {
                format!("neumann, g = ({}, {})", short(g.0[0].text()), short(g.0[1].text()))
            }
            PartKind::Contact(g, None) => format!("contact u.n = 0, Tresca g_a = {}", short(g.text())),
            PartKind::Contact(g, Some(n)) => {
                format!("contact u.n = {}, Tresca g_a = {}", short(n.text()), short(g.text()))
            }
        };
        say!("part       {:<10} {:>6} edges  {}", part.name, n, what);
    }
    say!(
        "unknowns   {} (paper's count 2(edges - Dirichlet edges) = {}), {} contact unknowns",
        sp.n_dofs,
        sp.paper_dofs(),
        sp.contact.len()
    );
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
    say!("assembled  {}", terms.join(", "));
    say!(
        "time       {} steps on [{}, {}]{}",
        problem.n_steps(),
        s.times[0],
        s.times.last().unwrap_or(&0.0),
        if s.uniform_time { " (uniform)" } else { "" }
    );
    say!("solver     {} (tol {:.1e}, max_iter {})", s.solver.method.name(), s.solver.tol, s.solver.max_iter());
    say!("exact      {}", if s.exact.is_some() { "given: true errors computed" } else { "none" });
    say!("estimate   {}", estimate.describe());
    if let Some(j) = &json {
        let mut summary = super::summary::Summary::new("check", &s.file, start.elapsed().as_secs_f64());
        summary.check = Some(super::summary::CheckSummary {
            vertices: m.points.len(),
            triangles: m.tris.len(),
            edges: m.edges.len(),
            h: m.h_max(),
            unknowns: sp.n_dofs,
            paper_dofs: sp.paper_dofs(),
            contact_unknowns: sp.contact.len(),
            steps: problem.n_steps(),
            solver: s.solver.method.name().into(),
            tol: s.solver.tol,
            max_iter: s.solver.max_iter(),
            exact: s.exact.is_some(),
            setup: problem.setup.into(),
            memory: estimate.memory,
            disk: estimate.disk,
        });
        super::summary::write(j, &summary)?;
    }
    match super::out::stdout_error() {
        Some(e) => anyhow::bail!("cannot write to standard output: {e}"),
        None => Ok(()),
    }
}

//! The `tresca-cr` command line: `check`, `run`, `study`. Library errors become messages and exit codes here.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use tresca_cr::scene::PartKind;
use tresca_cr::{Problem, Scene};

#[derive(Parser)]
#[command(name = "tresca-cr", version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("TRESCA_BUILD_COMMIT"), ")"), about = "Quasi-static Tresca contact with stabilised Crouzeix-Raviart elements")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Validate a scene and print what it will model.
    Check {
        scene: PathBuf,
        #[arg(long)]
        refine: Option<u32>,
        #[arg(long)]
        steps: Option<usize>,
    },
    /// Run a scene.
    Run {
        scene: PathBuf,
        /// Uniform refinements (overrides mesh.refine).
        #[arg(long)]
        refine: Option<u32>,
        /// Uniform time steps (overrides time.steps).
        #[arg(long)]
        steps: Option<usize>,
        /// Per-step solver (overrides solver.method): ssn, uzawa or pdas.
        #[arg(long)]
        solver: Option<String>,
        /// Solver tolerance (overrides solver.tol).
        #[arg(long)]
        tol: Option<f64>,
        #[command(flatten)]
        out: OutputArgs,
        /// Print one line per step.
        #[arg(long, short)]
        verbose: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
    /// Convergence study: run the scene at several levels and print/write errors and observed orders.
    Study {
        scene: PathBuf,
        /// Levels as refine:steps, comma separated, e.g. 0:40,1:80,2:160,3:320.
        #[arg(long, value_delimiter = ',', required = true)]
        levels: Vec<tresca_cr::study::Level>,
        /// A finer reference run (refine:steps) to measure errors against.
        #[arg(long)]
        reference: Option<tresca_cr::study::Level>,
        /// Per-step solver (overrides solver.method).
        #[arg(long)]
        solver: Option<String>,
        /// Solver tolerance (overrides solver.tol).
        #[arg(long)]
        tol: Option<f64>,
        /// Write the table as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
}

/// Apply the --solver and --tol overrides.
fn solver_overrides(s: &mut Scene, solver: Option<String>, tol: Option<f64>) -> Result<()> {
    if let Some(m) = solver {
        s.solver.method = method(&m)?;
    }
    if let Some(t) = tol {
        anyhow::ensure!(t.is_finite() && t > 0.0, "--tol {t}: must be a positive number");
        s.solver.tol = t;
    }
    Ok(())
}

fn method(name: &str) -> Result<tresca_cr::scene::Method> {
    Ok(match name {
        "ssn" => tresca_cr::scene::Method::Ssn,
        "uzawa" => tresca_cr::scene::Method::Uzawa,
        "pdas" => tresca_cr::scene::Method::Pdas,
        other => anyhow::bail!("--solver {other}: expected ssn, uzawa or pdas"),
    })
}

fn study(
    scene: Scene,
    levels: &[tresca_cr::study::Level],
    reference: Option<tresca_cr::study::Level>,
    csv: Option<PathBuf>,
) -> Result<()> {
    use tresca_cr::study::orders::observed_order;
    use tresca_cr::study::{csv_row, run_study, CSV_HEADER};
    println!(
        "{:>3} {:>6} {:>9} {:>9} {:>8} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>8}",
        "ref", "steps", "h", "k", "DOF", "energy", "ord", "L2", "ord", "consec(T)", "ord", "vs ref(T)", "ord", "wall s"
    );
    let mut prev: Option<tresca_cr::study::LevelResult> = None;
    let results = run_study(&scene, levels, reference, |r| {
        let o = |f: &dyn Fn(&tresca_cr::study::LevelResult) -> Option<f64>| match (&prev, f(r)) {
            // orders against h, or against k when only the time step changes
            (Some(p), Some(b)) => {
                let (xa, xb) = if (p.h - r.h).abs() <= 1e-12 * r.h { (p.k, r.k) } else { (p.h, r.h) };
                f(p).map(|a| format!("{:.3}", observed_order(a, b, xa, xb))).unwrap_or_default()
            }
            _ => String::new(),
        };
        let v = |x: Option<f64>| x.map(|x| format!("{x:.4e}")).unwrap_or_else(|| "-".into());
        let en = |r: &tresca_cr::study::LevelResult| r.max_err.map(|e| e.energy);
        let l2 = |r: &tresca_cr::study::LevelResult| r.max_err.map(|e| e.l2);
        let co = |r: &tresca_cr::study::LevelResult| r.consecutive.map(|e| e[1]);
        let rf = |r: &tresca_cr::study::LevelResult| r.reference.map(|e| e[1]);
        println!(
            "{:>3} {:>6} {:>9.3e} {:>9.3e} {:>8} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>11} {:>6} {:>8.3}",
            r.refine,
            r.steps,
            r.h,
            r.k,
            r.paper_dofs,
            v(en(r)),
            o(&en),
            v(l2(r)),
            o(&l2),
            v(co(r)),
            o(&co),
            v(rf(r)),
            o(&rf),
            r.wall
        );
        prev = Some(r.clone());
    })?;
    if let Some(path) = csv {
        let mut text = String::from(CSV_HEADER);
        text.push('\n');
        for r in &results {
            text += &csv_row(r);
            text.push('\n');
        }
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// Where and how results are written.
#[derive(clap::Args)]
struct OutputArgs {
    /// Results file (HDF5, with a run.xdmf sidecar); overrides the scene's [output] path.
    #[arg(long, short = 'o')]
    output: Option<PathBuf>,
    /// Overwrite an existing results file.
    #[arg(long, conflicts_with = "resume")]
    force: bool,
    /// Continue the run held in the results file from its last complete step.
    #[arg(long)]
    resume: bool,
    /// Visualisation frame (VTKHDF/XDMF) every k steps, plus the last; default about 50 frames in all.
    #[arg(long)]
    frame_every: Option<usize>,
    /// Seconds between commits (write + flush) of completed steps; 0 (default) commits every step.
    #[arg(long, default_value_t = 0.0)]
    commit_interval: f64,
}

fn load(path: &PathBuf, refine: Option<u32>, steps: Option<usize>) -> Result<Scene> {
    let mut scene = Scene::from_file(path)?;
    if scene.rho < 1.0 {
        // a_h is coercive only through the jump term (plain CR fails Korn's inequality): the discrete
        // Korn constant, and with it the error, degrades like 1/ρ (reference/stability.md: ρ = 1e-4 gives
        // L² errors 2000 times those of ρ = 10 on mms_elastic)
        eprintln!(
            "warning: {}: rho = {} < 1 weakens the jump stabilisation that makes Crouzeix-Raviart elasticity stable; expect large errors",
            scene.file, scene.rho
        );
    }
    if let Some(k) = refine {
        scene.set_refine(k)?;
    }
    if let Some(n) = steps {
        scene.set_steps(n)?;
    }
    Ok(scene)
}

/// An expression for display: long generated expressions are shortened.
fn short(text: &str) -> String {
    if text.chars().count() <= 48 {
        text.to_string()
    } else {
        format!("{}… ({} characters)", text.chars().take(40).collect::<String>(), text.chars().count())
    }
}

fn check(scene: Scene) -> Result<()> {
    let problem = Problem::new(scene)?;
    let (s, m, sp) = (&problem.scene, &problem.mesh, &problem.space);
    println!("scene      {} ({})", s.file, if s.title.is_empty() { "untitled" } else { &s.title });
    println!(
        "mesh       {} vertices, {} triangles, {} edges, h = {:.4e}",
        m.points.len(),
        m.tris.len(),
        m.edges.len(),
        m.h_max()
    );
    println!(
        "material   E = {}, nu = {} (plane strain: lambda = {:.6e}, mu = {:.6e})",
        s.material.e, s.material.nu, problem.law.lam, problem.law.mu
    );
    for (p, part) in s.parts.iter().enumerate() {
        let n = sp.edge_part.iter().filter(|&&q| q == Some(p)).count();
        let what = match &part.kind {
            PartKind::Dirichlet => "dirichlet (u = 0)".to_string(),
            PartKind::Neumann(None) => "neumann, traction free (nothing assembled)".to_string(),
            PartKind::Neumann(Some(g)) => {
                format!("neumann, g = ({}, {})", short(g.0[0].text()), short(g.0[1].text()))
            }
            PartKind::Contact(g) => format!("contact u.n = 0, Tresca g_a = {}", short(g.text())),
        };
        println!("part       {:<10} {:>6} edges  {}", part.name, n, what);
    }
    println!(
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
    println!("assembled  {}", terms.join(", "));
    println!(
        "time       {} steps on [{}, {}]{}",
        problem.n_steps(),
        s.times[0],
        s.times.last().unwrap_or(&0.0),
        if s.uniform_time { " (uniform)" } else { "" }
    );
    println!("solver     {} (tol {:.1e}, max_iter {})", s.solver.method.name(), s.solver.tol, s.solver.max_iter());
    println!("exact      {}", if s.exact.is_some() { "given: true errors computed" } else { "none" });
    Ok(())
}

fn run(scene: Scene, out: OutputArgs, verbose: bool, quiet: bool) -> Result<()> {
    use tresca_cr::output::{Options, Run, Writer};
    let start = std::time::Instant::now();
    let path = out.output.clone().or_else(|| scene.output.clone());
    anyhow::ensure!(!(out.resume && path.is_none()), "--resume needs a results file: give -o FILE");
    anyhow::ensure!(out.frame_every != Some(0), "--frame-every must be at least 1");
    anyhow::ensure!(
        out.commit_interval.is_finite() && out.commit_interval >= 0.0,
        "--commit-interval must be a non-negative number of seconds"
    );
    let problem = Problem::new(scene)?;
    let info = Run::of(&problem);
    let (mut writer, first) = match &path {
        Some(p) if out.resume => {
            let (mut w, last) = Writer::resume(p, &info)?;
            w.set_commit_interval(out.commit_interval);
            match &last {
                Some(l) => eprintln!("resuming {} after step {} of {}", p.display(), l.n, problem.n_steps()),
                None => eprintln!("{}: no step was committed before; running from step 0", p.display()),
            }
            (Some(w), last)
        }
        Some(p) => {
            let opts = Options { force: out.force, frame_every: out.frame_every, commit_interval: out.commit_interval };
            (Some(Writer::create_with(p, &info, &opts)?), None)
        }
        None => (None, None),
    };
    let n = problem.n_steps();
    let all = writer.is_some() || problem.scene.exact.is_some() || verbose;
    let bar = if quiet || verbose || n < 50 {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(n as u64)
    };
    let mut max_err = tresca_cr::fem::norms::ErrorNorms::default();
    let (mut iters, mut max_res) = (0usize, 0.0f64);
    let mut last = None;
    let on_step = |r: &tresca_cr::StepResult| -> tresca_cr::Result<()> {
        if let Some(w) = writer.as_mut() {
            w.write_step(r)?;
        }
        if let Some(e) = r.errors {
            max_err = max_err.max(e);
        }
        iters += r.iterations;
        max_res = max_res.max(r.residual);
        if verbose {
            let err = r.errors.map(|e| format!("  |||e||| {:.4e}  L2 {:.4e}", e.energy, e.l2)).unwrap_or_default();
            println!(
                "step {:>5} t = {:<10.6} it {:>5} res {:.2e} stick {:>4} slip {:>4}{}",
                r.n,
                r.t,
                r.iterations,
                r.residual,
                r.n_stick(),
                r.n_slip(),
                err
            );
        }
        bar.inc(u64::from(r.n > 0));
        last = Some(r.clone());
        Ok(())
    };
    // Without a results file and without true errors, u is formed only at the last step: every step still
    // solves the friction problem (slip, μ, stick/slip), but reconstructing u costs O(n·n_c) per step.
    let want = |k: usize| all || k == n;
    let result = match first {
        Some(f) => problem.run_selected(f, want, on_step),
        None => problem.initial().and_then(|f| {
            let mut on_step = on_step;
            on_step(&f)?;
            problem.run_selected(f, want, on_step)
        }),
    };
    let status = result.as_ref().map_or_else(|e| format!("stopped: {e}"), |()| "completed".to_string());
    let committed = writer.map(|w| w.finish(&status)).transpose()?;
    if let (Err(_), Some(p)) = (&result, &path) {
        let p = p.display();
        match committed {
            Some(0) => {
                eprintln!("no step was committed, so no results file was written (an existing {p} is left as it was)")
            }
            _ => eprintln!("every completed step is in {p}; its `tresca` group records why the run stopped"),
        }
    }
    result.with_context(|| "run stopped")?;
    bar.finish_and_clear();
    let sp = &problem.space;
    println!("unknowns {} (paper DOF {}), contact edges {}, steps {}", sp.n_dofs, sp.paper_dofs(), sp.contact.len(), n);
    let st = problem.setup;
    println!(
        "set-up: mesh {:.3}s, assembly {:.3}s, factorisation {:.3}s, condensation {:.3}s",
        st.space, st.assembly, st.factorisation, st.condensation
    );
    println!(
        "solver {}: {} iterations in all, max residual {:.2e}; wall time {:.3}s",
        problem.scene.solver.method.name(),
        iters,
        max_res,
        start.elapsed().as_secs_f64()
    );
    if let Some(r) = last {
        if !r.state.is_empty() {
            println!("final step: {} stick, {} slip contact edges", r.n_stick(), r.n_slip());
        }
    }
    if problem.scene.exact.is_some() {
        println!(
            "max over time nodes: energy error {:.6e}, H1 error {:.6e}, L2 error {:.6e}",
            max_err.energy, max_err.h1, max_err.l2
        );
    }
    Ok(())
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.cmd {
        Cmd::Check { scene, refine, steps } => load(&scene, refine, steps).and_then(check),
        Cmd::Run { scene, refine, steps, solver, tol, out, verbose, quiet } => {
            load(&scene, refine, steps).and_then(|mut s| {
                solver_overrides(&mut s, solver, tol)?;
                run(s, out, verbose, quiet)
            })
        }
        Cmd::Study { scene, levels, reference, solver, tol, csv } => load(&scene, None, None).and_then(|mut s| {
            solver_overrides(&mut s, solver, tol)?;
            study(s, &levels, reference, csv)
        }),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

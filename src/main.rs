//! The `tresca-cr` command line: `check`, `run`, `study`, `plan`, `adapt`. Library errors become messages and exit codes here.

mod cli;

use anyhow::Result;
use clap::{Parser, Subcommand};
use cli::out::note;
use cli::run::OutputArgs;
use std::path::{Path, PathBuf};
use tresca_cr::scene::budget::Estimate;
use tresca_cr::scene::Method;
use tresca_cr::Scene;

#[derive(Parser)]
#[command(name = "tresca-cr", version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("TRESCA_BUILD_COMMIT"), ")"), about = "Quasi-static Tresca contact with stabilised Crouzeix-Raviart elements")]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
    /// Threads of the factorisation, the large solves and the expression evaluation (default:
    /// TRESCA_THREADS, else the cores available to the process).
    #[arg(long, global = true, value_parser = cli::args::at_least_one)]
    threads: Option<usize>,
}

#[derive(Subcommand)]
enum Cmd {
    /// Validate a scene and print what it will model, with the memory and disk a run will need.
    Check {
        scene: PathBuf,
        #[command(flatten)]
        grid: Grid,
        #[command(flatten)]
        limits: Limits,
        #[command(flatten)]
        json: cli::summary::Reports,
    },
    /// Run a scene.
    Run {
        scene: PathBuf,
        #[command(flatten)]
        overrides: Overrides,
        #[command(flatten)]
        out: OutputArgs,
        /// Print one line per step.
        #[arg(long, short)]
        verbose: bool,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
        #[command(flatten)]
        limits: Limits,
        #[command(flatten)]
        json: cli::summary::JsonArg,
    },
    /// Convergence study: run the scene at several levels and print/write errors and observed orders.
    Study {
        scene: PathBuf,
        /// Levels as refine:steps, comma separated, e.g. 0:40,1:80,2:160,3:320.
        #[arg(long, value_delimiter = ',', required = true, allow_hyphen_values = true, value_parser = cli::args::level)]
        levels: Vec<tresca_cr::study::Level>,
        /// A finer reference run (refine:steps) to measure errors against.
        #[arg(long, allow_hyphen_values = true, value_parser = cli::args::level)]
        reference: Option<tresca_cr::study::Level>,
        #[command(flatten)]
        solver: SolverArgs,
        /// Write the table as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write per level the elementwise energy density of u_l − P u_{l−1} (XDMF, ParaView) into DIR.
        #[arg(long, value_name = "DIR")]
        differences: Option<PathBuf>,
        /// Refuse a study whose levels' estimated peak memory exceeds this (default: available memory).
        #[arg(long, allow_hyphen_values = true, value_parser = cli::args::size)]
        max_memory: Option<u64>,
        #[command(flatten)]
        json: cli::summary::Reports,
    },
    /// Adaptive meshes: solve, estimate the error per triangle, mark (Dörfler) and bisect, level by
    /// level, each level a whole run; a table per level (exit code 3 when stopped before the goal).
    Adapt {
        scene: PathBuf,
        /// Stop once the error estimate is at most this (energy norm, max over the time nodes; from level 4 on).
        #[arg(long, required_unless_present = "levels", allow_hyphen_values = true, value_parser = cli::args::positive)]
        target: Option<f64>,
        /// Number of levels (solves), the starting mesh included.
        #[arg(long, allow_negative_numbers = true, value_parser = cli::args::at_least_one)]
        levels: Option<usize>,
        /// Dörfler's parameter: mark the fewest triangles carrying this share of η².
        #[arg(long, default_value_t = 0.5, allow_hyphen_values = true, value_parser = cli::args::theta)]
        theta: f64,
        // --refine: of the starting mesh
        #[command(flatten)]
        overrides: Overrides,
        /// Write DIR/level_<k>.h5, each level's results file with its mesh.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Overwrite existing level files.
        #[arg(long)]
        force: bool,
        /// With --out: also write each level's mesh as DIR/level_<k>.msh (Gmsh 4.1 ASCII).
        #[arg(long, requires = "out")]
        gmsh: bool,
        /// Write the table as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Wall time the whole loop may take (e.g. 90s, 10m).
        #[arg(long, allow_hyphen_values = true, value_parser = cli::plan::parse_duration)]
        budget: Option<f64>,
        /// Measure every level against a reference solution on the finest mesh refined until every
        /// triangle has at least this bisection generation (a uniform mesh of that generation nests in it).
        #[arg(long, value_name = "GENERATION", allow_negative_numbers = true, value_parser = cli::args::generation)]
        reference: Option<u32>,
        #[command(flatten)]
        limits: Limits,
        #[command(flatten)]
        json: cli::summary::JsonArg,
    },
    /// Plan the cheapest run that meets a target accuracy: pilot runs, error and cost models, the
    /// cheapest (refine, steps, solver, tolerance) and two runners-up, or a refusal (exit code 3).
    Plan {
        scene: PathBuf,
        /// The error to reach (absolute, in the quantity's units).
        #[arg(long, allow_negative_numbers = true)]
        target: f64,
        /// energy-norm (the energy-norm error, max over the time nodes), or an output of [quantities] at T:
        /// max-slip, stick-length, contact-length, max-pressure (these two with unilateral or Coulomb contact),
        /// elastic-energy (½a_h(u,u)) or traction_x_y.
        #[arg(long, default_value = "energy-norm")]
        quantity: String,
        /// Wall time the planned run may take (e.g. 90s, 10m, 2h).
        #[arg(long, default_value = "1h", allow_hyphen_values = true, value_parser = cli::plan::parse_duration)]
        budget: f64,
        /// Wall time the pilot runs may take (default: a tenth of the budget).
        #[arg(long, allow_hyphen_values = true, value_parser = cli::plan::parse_duration)]
        pilot_budget: Option<f64>,
        /// Run the plan and report the achieved error estimate (and the true error with [exact]).
        #[arg(long)]
        run: bool,
        /// Write the plan and the runners-up as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Refuse configurations whose estimated peak memory exceeds this (default: available memory).
        #[arg(long, allow_hyphen_values = true, value_parser = cli::args::size)]
        max_memory: Option<u64>,
        /// Plan uniform refinement only: do not pilot and weigh the adaptive route (`adapt`).
        #[arg(long)]
        uniform_only: bool,
        #[command(flatten)]
        json: cli::summary::Reports,
    },
}

/// Limits on what a run may use (default: what the machine has).
#[derive(clap::Args, Clone, Copy)]
struct Limits {
    /// Refuse a run whose estimated peak memory exceeds this (e.g. 800M, 16G; default: available memory).
    #[arg(long, allow_hyphen_values = true, value_parser = cli::args::size)]
    max_memory: Option<u64>,
    /// Refuse a run whose estimated results file exceeds this (e.g. 2G; default: free disk space).
    #[arg(long, allow_hyphen_values = true, value_parser = cli::args::size)]
    max_disk: Option<u64>,
}

impl Limits {
    /// No limit given (the commands that estimate per level themselves).
    fn none() -> Limits {
        Limits { max_memory: None, max_disk: None }
    }
}

/// --refine and --steps: the scene's mesh and time grid overridden.
#[derive(clap::Args, Clone, Copy, Default)]
struct Grid {
    /// Uniform refinements (overrides mesh.refine; adapt: of the starting mesh).
    #[arg(long, allow_negative_numbers = true, value_parser = cli::args::refine)]
    refine: Option<u32>,
    /// Uniform time steps (overrides time.steps).
    #[arg(long, allow_negative_numbers = true, value_parser = cli::args::count)]
    steps: Option<usize>,
}

/// --solver and --tol: the scene's per-step solver overridden.
#[derive(clap::Args, Clone, Copy)]
struct SolverArgs {
    /// Per-step solver (overrides solver.method).
    #[arg(long)]
    solver: Option<Method>,
    /// Solver tolerance (overrides solver.tol).
    #[arg(long, allow_negative_numbers = true)]
    tol: Option<f64>,
}

/// The overrides of a command that runs a scene: --refine, --steps, --solver, --tol.
#[derive(clap::Args, Clone, Copy)]
struct Overrides {
    #[command(flatten)]
    grid: Grid,
    #[command(flatten)]
    solver: SolverArgs,
}

impl SolverArgs {
    /// Apply the --solver and --tol overrides.
    fn apply(self, s: &mut Scene) -> Result<()> {
        if let Some(m) = self.solver {
            s.solver.method = m;
        }
        if let Some(t) = self.tol {
            anyhow::ensure!(t.is_finite() && t > 0.0, "--tol {t}: must be a positive number");
            s.solver.tol = t;
        }
        Ok(())
    }
}

/// Read the scene, estimate what the run needs (refused when it does not fit: before anything large is
/// allocated), then apply --refine and --steps. `output`: the results file, if one is written; `creates`:
/// this process will create it (`run`), so a path that cannot be a results file is refused first.
fn load(
    path: &Path,
    Grid { refine, steps }: Grid,
    limits: Limits,
    output: impl FnOnce(&Scene) -> Option<PathBuf>,
    creates: bool,
) -> Result<(Scene, Estimate)> {
    let mut scene = Scene::from_file(path)?;
    for d in &scene.deprecations {
        note!("warning: {d}");
    }
    // the results file whose disk the estimate is for, chosen from the scene just read (parsed once)
    let output = output(&scene);
    let output = output.as_deref();
    if let Some(p) = output.filter(|_| creates) {
        tresca_cr::output::check_target(p, false)?;
        tresca_cr::output::check_writable(p)?;
    }
    if scene.rho < 1.0 {
        // a_h is coercive only through the jump term (plain CR fails Korn's inequality): the discrete
        // Korn constant, and with it the error, degrades like 1/ρ (reference/stability.md: ρ = 1e-4 gives
        // L² errors 2000 times those of ρ = 10 on mms_elastic)
        note!(
            "warning: {}: rho = {} < 1 weakens the jump stabilisation that makes Crouzeix-Raviart elasticity stable; expect large errors",
            scene.file, scene.rho
        );
    }
    if let Some(k) = refine {
        scene.set_refine(k)?;
    }
    if steps.is_some() && !scene.uniform_time {
        scene.set_steps(1)?; // refused with the reason
    }
    let n = steps.unwrap_or(scene.times.len() - 1);
    let dir = output.map(|p| p.parent().unwrap_or(Path::new(".")).to_path_buf());
    let estimate = Estimate::of(&scene, n, output.is_some())?;
    estimate.check(limits.max_memory, limits.max_disk, dir.as_deref())?;
    if let Some(n) = steps {
        scene.set_steps(n)?;
    }
    // the one validation of every command, before any work (each set-up checks its own level again)
    tresca_cr::fem::validate::scene(&scene)?;
    Ok((scene, estimate))
}

fn main() {
    cli::malloc::tune();
    let cli = Cli::parse();
    let threads = tresca_cr::threads::requested(cli.threads).and_then(tresca_cr::threads::set);
    let result = threads.map_err(anyhow::Error::from).and_then(|()| match cli.cmd {
        Cmd::Check { scene, grid, limits, json } => check(&scene, grid, limits, json),
        Cmd::Run { scene, overrides, out, verbose, quiet, limits, json } => {
            run(&scene, overrides, out, (verbose, quiet), limits, json)
        }
        Cmd::Study { scene, levels, reference, solver, csv, differences, max_memory, json } => {
            cli::summary::check_path(json.json.as_deref())
                .and_then(|()| load(&scene, Grid::default(), Limits::none(), |_| None, false))
                .and_then(|(mut s, _)| {
                    solver.apply(&mut s)?;
                    cli::study::study(s, &levels, reference, csv, differences, max_memory, json)
                })
        }
        cmd @ Cmd::Adapt { .. } => adapt(cmd),
        cmd @ Cmd::Plan { .. } => plan(cmd),
    });
    if let Err(e) = result {
        note!("error: {e:#}");
        std::process::exit(1);
    }
}

/// `check`: the estimate of the results file is for the scene's [output] path, else the current directory.
fn check(scene: &Path, grid: Grid, limits: Limits, json: cli::summary::Reports) -> Result<()> {
    let out = |s: &Scene| Some(s.output.clone().unwrap_or_else(|| PathBuf::from("run.h5")));
    cli::summary::check_path(json.json.as_deref())
        .and_then(|()| load(scene, grid, limits, out, false))
        .and_then(|(s, e)| cli::check::check(s, e, json))
}

/// `run`: a resumed run's file already holds its disk space, so only memory is checked then.
fn run(
    scene: &Path,
    overrides: Overrides,
    out: OutputArgs,
    (verbose, quiet): (bool, bool),
    limits: Limits,
    json: cli::summary::JsonArg,
) -> Result<()> {
    let (given, resume) = (out.output.clone(), out.resume);
    // an existing -o first: before the estimate, whose bounds (ulimit -v) would name another cause
    given.iter().filter(|_| !resume).try_for_each(|p| tresca_cr::output::Writer::refuse_existing(p, out.force))?;
    let new_file = move |s: &Scene| given.or_else(|| s.output.clone()).filter(|_| !resume);
    cli::summary::check_path(json.json.as_deref())
        .and_then(|()| load(scene, overrides.grid, limits, new_file, true))
        .and_then(|(mut s, _)| {
            overrides.solver.apply(&mut s)?;
            cli::run::run(s, out, verbose, quiet, json.json)
        })
}

/// `adapt` (exits with its code when that is not 0).
fn adapt(cmd: Cmd) -> Result<()> {
    let Cmd::Adapt { scene, target, levels, theta, overrides, out, force, gmsh, csv, budget, reference, limits, json } =
        cmd
    else {
        unreachable!("adapt() is called with Cmd::Adapt")
    };
    let (mut s, _) = cli::summary::check_path(json.json.as_deref())
        .and_then(|()| load(&scene, overrides.grid, limits, |_| None, false))?;
    overrides.solver.apply(&mut s)?;
    let (max_memory, max_disk) = (limits.max_memory, limits.max_disk);
    let opts = tresca_cr::adapt::Options {
        levels,
        target,
        until_unknowns: None,
        theta,
        out,
        gmsh,
        force,
        max_memory,
        max_disk,
        budget,
        reference,
        lean: false,
    };
    exit_unless_zero(cli::adapt::run(s, opts, csv, json.json)?);
    Ok(())
}

/// `plan` (exits with its code when that is not 0).
fn plan(cmd: Cmd) -> Result<()> {
    let Cmd::Plan { scene, target, quantity, budget, pilot_budget, run, csv, max_memory, uniform_only, json } = cmd
    else {
        unreachable!("plan() is called with Cmd::Plan")
    };
    if let Some(d) = tresca_cr::plan::pilot::Quantity::deprecation(&quantity) {
        note!("warning: {d}");
    }
    let options = tresca_cr::plan::Options {
        target,
        quantity: tresca_cr::plan::pilot::Quantity::parse(&quantity),
        budget,
        pilot_budget: pilot_budget.unwrap_or(budget / 10.0),
        max_memory,
    };
    let (s, _) = cli::summary::check_path(json.json.as_deref())
        .and_then(|()| load(&scene, Grid::default(), Limits::none(), |_| None, false))?;
    exit_unless_zero(cli::plan::run(s, options, csv, run, !uniform_only, json)?);
    Ok(())
}

/// Exit with `code` unless it is 0 (a command's own exit code: 3 when stopped before the goal).
fn exit_unless_zero(code: i32) {
    if code != 0 {
        std::process::exit(code);
    }
}

//! `tresca-cr run`: solve a scene, writing every step to the results file as it completes.

use super::out::{note, say};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use tresca_cr::output::guard::Outputs;
use tresca_cr::{Problem, RunOptions, Scene};

/// Where and how results are written.
#[derive(clap::Args)]
pub struct OutputArgs {
    /// Results file (HDF5, with a run.xdmf sidecar); overrides the scene's [output] path.
    #[arg(long, short = 'o')]
    pub output: Option<PathBuf>,
    /// Overwrite an existing results file.
    #[arg(long, conflicts_with = "resume")]
    pub force: bool,
    /// Continue the run held in the results file from its last complete step.
    #[arg(long)]
    pub resume: bool,
    /// Visualisation frame (VTKHDF/XDMF) every k steps, plus the last; default about 50 frames in all.
    #[arg(long, allow_negative_numbers = true, value_parser = super::args::count)]
    pub frame_every: Option<usize>,
    /// Seconds between commits (write + flush) of completed steps; 0 (default) commits every step as soon
    /// as the writer thread has it (with the steps queued behind it).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true, value_parser = super::args::non_negative)]
    pub commit_interval: f64,
}

pub fn run(scene: Scene, out: OutputArgs, verbose: bool, quiet: bool, json: Option<PathBuf>) -> Result<()> {
    let start = std::time::Instant::now();
    let path = out.output.clone().or_else(|| scene.output.clone());
    check_output_args(&out, path.as_deref(), json.as_deref(), &scene)?;
    let (problem, writer, first) = set_up(scene, &out, path.as_deref())?;
    let mut writer = writer.map(tresca_cr::output::Background::spawn).transpose()?;
    let n = problem.n_steps();
    let all = writer.is_some() || problem.scene.exact.is_some() || verbose;
    let bar = if quiet || verbose || n < 50 {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(n as u64)
    };
    let mut tally = Tally::default();
    let mut step_stats = Vec::new();
    let on_step = |r: &tresca_cr::StepResult| -> tresca_cr::Result<()> {
        step_stats.push(super::summary::Step::of(r, &problem.space));
        if let Some(w) = writer.as_mut() {
            w.write_step(r)?;
        }
        tally.record(r, verbose);
        bar.inc(u64::from(r.n > 0));
        Ok(())
    };
    // Without a results file and without true errors, u is formed only at the last step: every step still
    // solves the friction problem (slip, μ, stick/slip), but reconstructing u costs O(n·n_c) per step.
    let want = |k: usize| all || k == n;
    let result = problem.run(RunOptions { after: first, want, audit: true }, on_step);
    if let Some(z) = problem.friction.as_ref().map(|f| f.zeroed_steps()).filter(|&z| z > 0) {
        note!(
            "note: at {z} steps the friction bound g_a was below the rounding of the load (its effect on the slip \
             under 1e-17 of the free slip) and was treated as zero: those steps are frictionless"
        );
    }
    let status = result.as_ref().map_or_else(|e| format!("stopped: {e}"), |()| "completed".to_string());
    let facts = Facts::of(&problem);
    let mut summary = json_summary(&facts, &tally, step_stats, &status, path.as_deref());
    if writer.is_some() {
        // The writer still commits the last frames and closes the file: meanwhile this thread hands the
        // problem's memory (the factor, K, the load basis: about 60 MB at 24,640 unknowns) back to the
        // system, which the process's exit would otherwise do alone after the file is closed.
        drop(problem);
        super::malloc::hand_back_memory();
    }
    let committed = writer.map(|w| w.finish(&status)).transpose()?;
    if let (Err(_), Some(p)) = (&result, &path) {
        let p = p.display();
        match committed {
            Some(0) => {
                note!("no step was committed, so no results file was written (an existing {p} is left as it was)")
            }
            _ => note!("every completed step is in {p}; its `tresca` group records why the run stopped"),
        }
    }
    if let Some(j) = &json {
        summary.wall = start.elapsed().as_secs_f64();
        super::summary::write(j, &summary, out.force)?;
    }
    result.with_context(|| "run stopped")?;
    bar.finish_and_clear();
    print_summary(&facts, &tally, n, start.elapsed().as_secs_f64());
    if let Some(e) = super::out::stdout_error() {
        // the run's result is its file: a closed or full standard output does not fail it
        let kept =
            path.map_or("no results file was asked for".to_string(), |p| format!("its results are in {}", p.display()));
        note!("warning: standard output could not be written ({e}); the run went on to its end and {kept}");
    }
    Ok(())
}

/// The output options that are refused before anything is done (every output under `output::guard`'s
/// rule), and the note for a run without a file.
fn check_output_args(out: &OutputArgs, path: Option<&Path>, json: Option<&Path>, scene: &Scene) -> Result<()> {
    anyhow::ensure!(!(out.resume && path.is_none()), "--resume needs a results file: give -o FILE");
    anyhow::ensure!(out.frame_every != Some(0), "--frame-every must be at least 1");
    anyhow::ensure!(
        out.commit_interval.is_finite() && out.commit_interval >= 0.0,
        "--commit-interval must be a non-negative number of seconds"
    );
    if let Some(p) = path.filter(|_| !out.resume) {
        tresca_cr::output::Writer::refuse_existing(p, out.force)?;
    }
    let outputs = Outputs::new(out.force).inputs_of(scene).files(json, "--json file");
    match path {
        Some(p) => outputs.results(p, "results file", out.resume).check()?,
        None => {
            outputs.check()?;
            note!("note: no results file (give -o FILE or an [output] path): the steps are solved and only this summary is kept")
        }
    }
    Ok(())
}

/// The problem set up, with the results file's writer (created beside the set-up, or reopened for
/// `--resume`) and the step a resumed run continues after.
fn set_up(
    scene: Scene,
    out: &OutputArgs,
    path: Option<&Path>,
) -> Result<(Problem, Option<tresca_cr::output::Writer>, Option<tresca_cr::StepResult>)> {
    use tresca_cr::output::{Options, Run, Writer};
    // the run owns its output path from here on (refused at once if another run has it)
    let lock = path.map(tresca_cr::output::OutputLock::acquire).transpose()?;
    // A new results file is created on a second thread while the solver is set up (its set-up times are
    // recorded once known); the steps are then written by a writer thread while the solver goes on.
    let opts = Options { force: out.force, frame_every: out.frame_every, commit_interval: out.commit_interval };
    let (problem, lock, created) = match lock {
        Some(lock) if !out.resume => {
            let (p, w) =
                Problem::new_beside(scene, move |p0| Writer::create_locked(lock, &Run::before_setup(p0), &opts));
            (p, None, w)
        }
        lock => (Problem::new(scene), lock, None),
    };
    let problem = problem?;
    let info = Run::of(&problem);
    let (writer, first) = match (path, lock, created) {
        (_, _, Some(w)) => {
            let mut w = w?;
            w.set_setup_times(&problem.setup)?;
            (Some(w), None)
        }
        (Some(p), Some(lock), None) => {
            let (mut w, last) = Writer::resume_locked(lock, &info)?;
            w.set_commit_interval(out.commit_interval);
            if let Some(k) = out.frame_every {
                note!("note: --frame-every {k} is ignored on --resume: the frames follow the file's own frame_every");
            }
            match &last {
                Some(l) => note!("resuming {} after step {} of {}", p.display(), l.n, problem.n_steps()),
                None => note!("{}: no step was committed before; running from step 0", p.display()),
            }
            (Some(w), last)
        }
        _ => (None, None),
    };
    Ok((problem, writer, first))
}

/// What the summary reports of the steps: the largest true errors, the iterations, the largest
/// residual, and the stick and slip edges of the last step (not the whole step, whose u is large).
#[derive(Default)]
struct Tally {
    max_err: tresca_cr::fem::norms::ErrorNorms,
    iters: usize,
    max_res: f64,
    /// the energy audit (stepping::audit): largest |balance residual| and the largest work of a step
    balance: f64,
    work: f64,
    last: Option<(usize, usize)>,
}

impl Tally {
    /// Count step `r` (and print its line when `verbose`).
    fn record(&mut self, r: &tresca_cr::StepResult, verbose: bool) {
        if let Some(e) = r.errors {
            self.max_err = self.max_err.max(e);
        }
        self.iters += r.iterations;
        self.max_res = self.max_res.max(r.residual);
        if let Some(a) = r.audit {
            self.balance = self.balance.max(a.balance_residual.abs());
            self.work = self.work.max(a.external_work.abs() + a.boundary_work.abs() + a.friction_dissipation);
        }
        if verbose {
            let err = r.errors.map(|e| format!("  |||e||| {:.4e}  L2 {:.4e}", e.energy, e.l2)).unwrap_or_default();
            say!(
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
        self.last = (!r.state.is_empty()).then(|| (r.n_stick(), r.n_slip()));
    }
}

/// What the summary says of the problem, kept once the problem is dropped.
struct Facts {
    file: String,
    refine: u32,
    tol: f64,
    steps: usize,
    dofs: usize,
    paper_dofs: usize,
    contact: usize,
    setup: tresca_cr::stepping::SetupTimes,
    ordering: &'static str,
    method: &'static str,
    exact: bool,
}

impl Facts {
    fn of(problem: &Problem) -> Facts {
        let sp = &problem.space;
        Facts {
            file: problem.scene.file.clone(),
            refine: problem.scene.mesh_level(),
            tol: problem.scene.solver.tol,
            steps: problem.n_steps(),
            dofs: sp.n_dofs,
            paper_dofs: sp.paper_dofs(),
            contact: sp.contact.len(),
            setup: problem.setup,
            ordering: problem.free.factor().ordering(),
            method: problem.scene.solver.method.name(),
            exact: problem.scene.exact.is_some(),
        }
    }
}

/// The machine-readable summary of the run (`--json`); its wall time is set when it is written.
fn json_summary(
    f: &Facts,
    t: &Tally,
    step_stats: Vec<super::summary::Step>,
    status: &str,
    path: Option<&Path>,
) -> super::summary::Summary {
    let mut summary = super::summary::Summary::new("run", &f.file, 0.0);
    summary.status = status.to_string();
    summary.run = Some(super::summary::RunSummary {
        refine: f.refine,
        unknowns: f.dofs,
        paper_dofs: f.paper_dofs,
        contact_edges: f.contact,
        steps: f.steps,
        solver: f.method.into(),
        tol: f.tol,
        setup: f.setup.into(),
        ordering: f.ordering.to_string(),
        step_stats,
        iterations: t.iters,
        max_residual: t.max_res,
        max_errors: f.exact.then_some(t.max_err.into()),
        output: path.map(|p| p.display().to_string()),
    });
    summary
}

/// The summary printed after a completed run.
fn print_summary(f: &Facts, t: &Tally, n: usize, wall: f64) {
    let st = f.setup;
    say!("unknowns {} (paper DOF {}), contact edges {}, steps {n}", f.dofs, f.paper_dofs, f.contact);
    say!(
        "set-up: mesh {:.3}s, assembly {:.3}s, factorisation {:.3}s, condensation {:.3}s, load superposition {:.3}s",
        st.space,
        st.assembly,
        st.factorisation,
        st.condensation,
        st.superposition
    );
    say!("fill-reducing ordering: {}", f.ordering);
    say!("solver {}: {} iterations in all, max residual {:.2e}; wall time {:.3}s", f.method, t.iters, t.max_res, wall);
    if t.work > 0.0 {
        say!(
            "energy balance: max |residual| {:.2e} ({:.1e} of the largest work of a step)",
            t.balance,
            t.balance / t.work
        );
    }
    if let Some((stick, slip)) = t.last {
        say!("final step: {stick} stick, {slip} slip contact edges");
    }
    if f.exact {
        say!(
            "max over time nodes: energy error {:.6e}, H1 error {:.6e}, L2 error {:.6e}",
            t.max_err.energy,
            t.max_err.h1,
            t.max_err.l2
        );
    }
}

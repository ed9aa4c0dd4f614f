//! `tresca-cr run`: solve a scene, writing every step to the results file as it completes.

use super::out::{note, say};
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use tresca_cr::{Problem, Scene};

/// Refuse output paths (`what`: the option) that are the scene or its mesh, as files (a link or another
/// name of them counts): writing them would overwrite the run's own input.
pub fn not_an_input(outs: &[PathBuf], scene: &Scene, what: &str) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let id = |p: &Path| std::fs::metadata(p).ok().map(|m| (m.dev(), m.ino()));
    let mut inputs = vec![PathBuf::from(&scene.file)];
    if let tresca_cr::scene::MeshSpec::Gmsh { path, .. } = &scene.mesh {
        inputs.push(path.clone());
    }
    for out in outs {
        let Some(o) = id(out) else { continue };
        if let Some(i) = inputs.iter().find(|i| id(i) == Some(o)) {
            anyhow::bail!(
                "{}: {what} would overwrite the run's input {}; choose another path",
                out.display(),
                i.display()
            );
        }
    }
    Ok(())
}

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

pub fn run(scene: Scene, out: OutputArgs, verbose: bool, quiet: bool) -> Result<()> {
    use tresca_cr::output::{Background, Options, Run, Writer};
    let start = std::time::Instant::now();
    let path = out.output.clone().or_else(|| scene.output.clone());
    anyhow::ensure!(!(out.resume && path.is_none()), "--resume needs a results file: give -o FILE");
    anyhow::ensure!(out.frame_every != Some(0), "--frame-every must be at least 1");
    anyhow::ensure!(
        out.commit_interval.is_finite() && out.commit_interval >= 0.0,
        "--commit-interval must be a non-negative number of seconds"
    );
    match &path {
        Some(p) => not_an_input(&[p.clone(), tresca_cr::output::sidecar(p)], &scene, "the output")?,
        None => note!("note: no results file (give -o FILE or an [output] path): the steps are solved and only this summary is kept"),
    }
    // the run owns its output path from here on (refused at once if another run has it)
    let lock = path.as_deref().map(tresca_cr::output::OutputLock::acquire).transpose()?;
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
    let (writer, first) = match (&path, lock, created) {
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
    let mut writer = writer.map(Background::spawn).transpose()?;
    let n = problem.n_steps();
    let all = writer.is_some() || problem.scene.exact.is_some() || verbose;
    let bar = if quiet || verbose || n < 50 {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(n as u64)
    };
    let mut max_err = tresca_cr::fem::norms::ErrorNorms::default();
    let (mut iters, mut max_res) = (0usize, 0.0f64);
    // stick and slip edges of the last step (for the summary; not the whole step, whose u is large)
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
        bar.inc(u64::from(r.n > 0));
        last = (!r.state.is_empty()).then(|| (r.n_stick(), r.n_slip()));
        Ok(())
    };
    // Without a results file and without true errors, u is formed only at the last step: every step still
    // solves the friction problem (slip, μ, stick/slip), but reconstructing u costs O(n·n_c) per step.
    let want = |k: usize| all || k == n;
    let result = match first {
        Some(f) => problem.run_selected(f, want, on_step),
        None => problem.run_all_selected(want, on_step),
    };
    if let Some(z) = problem.friction.as_ref().map(|f| f.zeroed_steps()).filter(|&z| z > 0) {
        note!(
            "note: at {z} steps the friction bound g_a was below the rounding of the load (its effect on the slip \
             under 1e-17 of the free slip) and was treated as zero: those steps are frictionless"
        );
    }
    let status = result.as_ref().map_or_else(|e| format!("stopped: {e}"), |()| "completed".to_string());
    let sp = &problem.space;
    let (dofs, paper_dofs, contact) = (sp.n_dofs, sp.paper_dofs(), sp.contact.len());
    let (st, method, exact) = (problem.setup, problem.scene.solver.method.name(), problem.scene.exact.is_some());
    if writer.is_some() {
        // The writer still commits the last frames and closes the file: meanwhile this thread hands the
        // problem's memory (the factor, K, the load basis: about 60 MB at 24,640 unknowns) back to the
        // system, which the process's exit would otherwise do alone after the file is closed.
        drop(problem);
        crate::hand_back_memory();
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
    result.with_context(|| "run stopped")?;
    bar.finish_and_clear();
    say!("unknowns {dofs} (paper DOF {paper_dofs}), contact edges {contact}, steps {n}");
    say!(
        "set-up: mesh {:.3}s, assembly {:.3}s, factorisation {:.3}s, condensation {:.3}s, load superposition {:.3}s",
        st.space,
        st.assembly,
        st.factorisation,
        st.condensation,
        st.superposition
    );
    say!(
        "solver {}: {} iterations in all, max residual {:.2e}; wall time {:.3}s",
        method,
        iters,
        max_res,
        start.elapsed().as_secs_f64()
    );
    if let Some((stick, slip)) = last {
        say!("final step: {stick} stick, {slip} slip contact edges");
    }
    if exact {
        say!(
            "max over time nodes: energy error {:.6e}, H1 error {:.6e}, L2 error {:.6e}",
            max_err.energy,
            max_err.h1,
            max_err.l2
        );
    }
    if let Some(e) = super::out::stdout_error() {
        // the run's result is its file: a closed or full standard output does not fail it
        let kept =
            path.map_or("no results file was asked for".to_string(), |p| format!("its results are in {}", p.display()));
        note!("warning: standard output could not be written ({e}); the run went on to its end and {kept}");
    }
    Ok(())
}

//! `tresca-cr run`: solve a scene, writing every step to the results file as it completes.

use anyhow::{Context, Result};
use std::path::PathBuf;
use tresca_cr::{Problem, Scene};

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
    #[arg(long)]
    pub frame_every: Option<usize>,
    /// Seconds between commits (write + flush) of completed steps; 0 (default) commits every step.
    #[arg(long, default_value_t = 0.0)]
    pub commit_interval: f64,
}

pub fn run(scene: Scene, out: OutputArgs, verbose: bool, quiet: bool) -> Result<()> {
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

//! `--resume`: reopen a results file of the same run and hand back the last
//! complete step so that stepping continues bit-identically (a step depends on the previous one only
//! through its slip and μ, both stored exactly). A run killed before its step 0 was committed left only
//! `.partial` files: it is started afresh.

use super::fields::Fields;
use super::h5::{self, io, Raw};
use super::lock::OutputLock;
use super::paths;
use super::reserve;
use super::tresca::Tresca;
use super::vtkhdf::{Frames, VtkHdf};
use super::xdmf::Xdmf;
use super::{ioerr, partial_path, Opened, Options, Run, Writer};
use crate::error::{Error, Result};
use crate::stepping::StepResult;
use std::path::Path;

impl Writer {
    /// Reopen a results file of `run` (same scene text, time grid, solver and mesh, else an error),
    /// and return the last complete step, from which `Problem::run_from` continues; `None` when the
    /// run starts afresh from step 0 in a new file.
    pub fn resume(path: &Path, run: &Run) -> Result<(Writer, Option<StepResult>)> {
        Writer::resume_locked(OutputLock::acquire(path)?, run)
    }

    /// [`Writer::resume`] on the path of a lock already taken.
    pub fn resume_locked(lock: OutputLock, run: &Run) -> Result<(Writer, Option<StepResult>)> {
        let path = lock.target().to_path_buf();
        let path = path.as_path();
        if !path.exists() {
            if partial_path(path).exists() {
                // killed before step 0 was committed (only `.partial` exists): start the same run afresh
                let opts = Options { force: true, ..Options::default() };
                return Ok((Writer::create_locked(lock, run, &opts)?, None));
            }
            return Err(Error::Io { path: path.to_path_buf(), msg: "no results file to --resume".into() });
        }
        paths::check_target(path, true)?;
        let file = hdf5::File::with_options()
            .with_fapl(h5::file_access)
            .open_rw(path)
            .map_err(io(path, "cannot open for --resume"))?;
        let raw = Raw::open(path).map_err(ioerr(path, "cannot open for --resume"))?;
        let mut tresca = Tresca::open(&file).map_err(io(path, "not a tresca-cr results file"))?;
        check_settings(&tresca.group, run, path)?;
        check_points(&tresca.group, run, path)?;
        let contact = (!run.space.contact.is_empty(), !run.space.normal_edges().is_empty());
        if contact.1 && !tresca.has_normal() {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: "--resume: the file holds no normal forces (tresca/contact/force, normal_dof) for a warm start \
                      of this unilateral or Coulomb run (written by an older version): rerun with --force"
                    .into(),
            });
        }
        if tresca.rigid_width() != run.rigid {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: format!(
                    "--resume: the file holds α for {} rigid motions (tresca/rigid), this floating body has {}: \
                     it was written by an older version or for another run; rerun with --force",
                    tresca.rigid_width(),
                    run.rigid
                ),
            });
        }
        let fields = Fields::new(run);
        check_views(&file, &fields, path)?;
        let mut vtk = VtkHdf::open(&file, contact).map_err(io(path, "VTKHDF group"))?;
        let (completed, times) = completed_steps(&mut tresca, run, path)?;
        let every = int(&tresca.group, "frame_every").max(1) as usize;
        let frames = Frames { every, last: run.n_steps() };
        let frames_done = frames.before(completed);
        let frame_list: Vec<(usize, f64)> =
            (0..completed).filter(|&n| frames.is_frame(n)).map(|n| (n, times[n])).collect();
        let misfit = tresca.misfit(run.space, completed);
        let short = (vtk.room() < frames_done).then(|| format!("the VTKHDF frame arrays hold {} frames", vtk.room()));
        let kept: Vec<f64> = frame_list.iter().map(|&(_, t)| t).collect();
        let lists = || VtkHdf::misfit(&file, &fields, contact, frames.total(), &kept);
        if let Some(what) = misfit.or(short).or_else(lists) {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: format!("--resume: {what}: the file was damaged after it was written; rerun with --force"),
            });
        }
        // a stopped run's series are given back their full length below: their room first (`reserve`)
        let rows = tresca.group.dataset("times").map_err(io(path, "tresca/times"))?.shape()[0];
        let len = raw.0.metadata().map_err(ioerr(path, "cannot inspect the file"))?.len();
        let all = run.n_steps() + 1;
        let need = (len as u128 * all.saturating_sub(rows) as u128 / rows.max(1) as u128) as u64 + reserve::MARGIN;
        reserve::ahead(&raw.0, need).map_err(|e| reserve::no_room(path, need, "to resume the run", &e))?;
        let mut fix = || -> hdf5::Result<StepResult> {
            // a stopped run's series were cut to its completed steps: room for the whole run again
            tresca.set_steps(&raw, run.n_steps() + 1, completed)?;
            vtk.set_frames(&raw, frames.total(), frames_done)?;
            tresca.set_completed(completed)?;
            vtk.set_nsteps(frames_done)?;
            tresca.set_status("running (resumed)")?;
            tresca.read_step(run.space, completed - 1)
        };
        let last = fix().map_err(io(path, "--resume"))?;
        let mut xdmf = Xdmf::resume(&file, path, &frame_list, contact, frames.total())
            .map_err(ioerr(path, "rewriting the XDMF sidecar"))?;
        file.flush().map_err(io(path, "flush"))?;
        xdmf.publish().map_err(ioerr(path, "cannot move the XDMF sidecar into place"))?;
        let prev_slip = Some(last.slip.clone());
        let opened = Opened { file, raw, tresca, vtk, xdmf, frames };
        let mut w = Writer::from_opened(path, run, fields, opened, completed, prev_slip);
        w.lock = Some(lock);
        Ok((w, Some(last)))
    }
}

/// An error for a file written for a different `what` than this run.
fn mismatch(path: &Path, what: &str) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        msg: format!("--resume: the file was written for a different {what}; rerun with --force to overwrite it"),
    }
}

/// The integer attribute `k` of the `/tresca` group (−1 when absent).
fn int(g: &hdf5::Group, k: &str) -> i64 {
    g.attr(k).and_then(|a| a.read_scalar::<i64>()).unwrap_or(-1)
}

/// Refuse a file whose run differs from `run` in a setting that changes the answer: the scene text, the
/// number of steps, the mesh's sizes, the solver and its settings (the scene text covers the rest).
fn check_settings(g: &hdf5::Group, run: &Run, path: &Path) -> Result<()> {
    let text = h5::read_str(g, "scene").map_err(io(path, "attribute scene"))?;
    if text != run.scene.text {
        return Err(mismatch(path, "scene (the stored scene text differs)"));
    }
    if int(g, "steps") != run.n_steps() as i64 {
        return Err(mismatch(path, "number of time steps (--steps)"));
    }
    if int(g, "n_edges") != run.mesh.edges.len() as i64 || int(g, "n_dofs") != run.space.n_dofs as i64 {
        return Err(mismatch(path, "mesh (--refine)"));
    }
    let solver = h5::read_str(g, "solver").unwrap_or_default();
    if solver != run.scene.solver.method.name() {
        return Err(mismatch(path, &format!("solver ({solver}, not {}: --solver)", run.scene.solver.method.name())));
    }
    let float = |k: &str| g.attr(k).and_then(|a| a.read_scalar::<f64>()).ok();
    let s = &run.scene.solver;
    for (key, stored, asked, option) in [
        ("tol", float("tol"), s.tol, "--tol / solver.tol"),
        ("uzawa_step", float("uzawa_step"), s.uzawa_step, "solver.uzawa_step"),
        ("rho", float("rho"), run.scene.rho, "discretisation.rho"),
    ] {
        if stored.map(f64::to_bits) != Some(asked.to_bits()) {
            let was = stored.map_or("none".to_string(), |v| format!("{v:e}"));
            return Err(mismatch(
                path,
                &format!("{key} ({option}: the file's steps were solved with {was}, this run asks {asked:e})"),
            ));
        }
    }
    if int(g, "max_iter") != s.max_iter() as i64 {
        return Err(mismatch(path, &format!("max_iter ({} in the file, {} asked)", int(g, "max_iter"), s.max_iter())));
    }
    Ok(())
}

/// Refuse a file whose stored vertex coordinates are not those of `run`'s mesh.
fn check_points(g: &hdf5::Group, run: &Run, path: &Path) -> Result<()> {
    let pts = g.dataset("mesh/points").and_then(|d| d.read_raw::<f64>()).map_err(io(path, "mesh/points"))?;
    if pts == run.mesh.points.as_flattened() {
        return Ok(());
    }
    // the scene text and the mesh's sizes are the file's: the coordinates come from them, unless a
    // Gmsh file they name was edited since
    let msg = match &run.scene.mesh {
        crate::mesh::MeshSpec::Gmsh { path: m, .. } => format!(
            "--resume: the stored vertex coordinates (tresca/mesh/points) differ from those of {}: the mesh \
             file was changed since the run, or the results file was damaged; rerun with --force",
            m.display()
        ),
        _ => "--resume: the stored vertex coordinates (tresca/mesh/points) differ from the mesh the scene \
              (the file's own text) generates: the file was damaged after it was written; rerun with --force"
            .into(),
    };
    Err(Error::Io { path: path.to_path_buf(), msg })
}

/// Refuse a file whose ParaView view (`VTKHDF/{body,contact}`) lists other numbers of points or cells than
/// `fields` has: its frames' rows, a block of points or cells each, would be written out of place.
fn check_views(file: &hdf5::File, fields: &Fields, path: &Path) -> Result<()> {
    for (block, np, per_cell) in [("body", fields.points.len(), 3), ("contact", fields.contact_points.len(), 2)] {
        for (list, want) in [("Points", np), ("Types", np / per_cell)] {
            let name = format!("VTKHDF/{block}/{list}");
            let have = file.dataset(&name).map(|d| d.shape().first().copied());
            if np > 0 && !matches!(have, Ok(Some(n)) if n == want) {
                let have =
                    have.map_or("nothing (missing)".into(), |n| n.map_or("a scalar".into(), |n| format!("{n} rows")));
                return Err(Error::Io {
                    path: path.to_path_buf(),
                    msg: format!(
                        "--resume: {name} holds {have}, this run's mesh has {want}: the file was damaged after \
                         it was written; rerun with --force"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// The file's committed steps and its time nodes, refused when there are none, more than it has room
/// for, a step does not match its checksum, or their times are not `run`'s.
fn completed_steps(tresca: &mut Tresca, run: &Run, path: &Path) -> Result<(usize, Vec<f64>)> {
    let completed = tresca.completed().map_err(io(path, "tresca/steps completed"))?;
    if completed == 0 {
        return Err(Error::Io {
            path: path.to_path_buf(),
            msg: "--resume: the file holds no committed step (not written by this version); run again with --force"
                .into(),
        });
    }
    let times: Vec<f64> =
        tresca.group.dataset("times").and_then(|d| d.read_raw::<f64>()).map_err(io(path, "tresca/times"))?;
    if completed > run.n_steps() + 1 || completed > times.len() {
        return Err(Error::Io {
            path: path.to_path_buf(),
            msg: format!(
                "--resume: the file's counter of committed steps (tresca/steps completed = {completed}) exceeds the \
                 {} steps it has room for: the file was damaged after it was written; rerun with --force",
                times.len().min(run.n_steps() + 1)
            ),
        });
    }
    // storage corruption since the steps were written: refuse, naming the first bad step
    if let Some(n) = tresca.first_corrupt_step(completed).map_err(io(path, "--resume: verifying the step checksums"))? {
        return Err(Error::Io {
            path: path.to_path_buf(),
            msg: format!(
                "--resume: step {n} does not match its checksum (tresca/steps/checksum): the file was \
                 damaged after it was written. Steps 0..{} are intact; rerun with --force",
                n as i64 - 1
            ),
        });
    }
    // the steps match their checksums, so these are the times they were solved at
    if times[..completed] != run.scene.times[..completed] {
        return Err(mismatch(path, "time grid"));
    }
    Ok((completed, times))
}

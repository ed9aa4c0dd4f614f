//! `--resume`: reopen a results file of the same run and hand back the last
//! complete step so that stepping continues bit-identically (a step depends on the previous one only
//! through its slip and μ, both stored exactly).

use super::*;

impl Writer {
    /// Reopen a results file of `problem` (same scene text, time grid, solver and mesh, else an error),
    /// and return the last complete step, from which `problem.run_from` continues.
    pub fn resume(path: &Path, problem: &Problem) -> Result<(Writer, StepResult)> {
        if !path.exists() {
            if partial_path(path).exists() {
                // killed before step 0 was committed (only `.partial` exists): start the same run afresh
                return Writer::afresh(path, problem);
            }
            return Err(Error::Io { path: path.to_path_buf(), msg: "no results file to --resume".into() });
        }
        let file = hdf5::File::with_options()
            .with_fapl(h5::file_access)
            .open_rw(path)
            .map_err(io(path, "cannot open for --resume"))?;
        let raw = Raw::open(path).map_err(ioerr(path, "cannot open for --resume"))?;
        let mut tresca = Tresca::open(&file).map_err(io(path, "not a tresca-cr results file"))?;
        let mismatch = |what: &str| Error::Io {
            path: path.to_path_buf(),
            msg: format!("--resume: the file was written for a different {what}; rerun with --force to overwrite it"),
        };
        let g = &*tresca.group;
        let text = h5::read_str(g, "scene").map_err(io(path, "attribute scene"))?;
        if text != problem.scene.text {
            return Err(mismatch("scene (the stored scene text differs)"));
        }
        let int = |k: &str| g.attr(k).and_then(|a| a.read_scalar::<i64>()).unwrap_or(-1);
        if int("steps") != problem.n_steps() as i64 {
            return Err(mismatch("number of time steps (--steps)"));
        }
        if int("n_edges") != problem.mesh.edges.len() as i64 || int("n_dofs") != problem.space.n_dofs as i64 {
            return Err(mismatch("mesh (--refine)"));
        }
        let solver = h5::read_str(g, "solver").unwrap_or_default();
        if solver != problem.scene.solver.method.name() {
            return Err(mismatch(&format!("solver ({solver})")));
        }
        let pts =
            tresca.group.dataset("mesh/points").and_then(|d| d.read_raw::<f64>()).map_err(io(path, "mesh/points"))?;
        if pts != problem.mesh.points.as_flattened() {
            return Err(mismatch("mesh (vertex coordinates)"));
        }
        let contact = !problem.space.contact.is_empty();
        let mut vtk = VtkHdf::open(&file, contact).map_err(io(path, "VTKHDF group"))?;
        let completed = tresca.completed().map_err(io(path, "tresca/steps completed"))?;
        if completed == 0 {
            // a file without a step (written by a version that moved files into place before step 0)
            drop((vtk, tresca, file));
            return Writer::afresh(path, problem);
        }
        let times: Vec<f64> =
            tresca.group.dataset("times").and_then(|d| d.read_raw::<f64>()).map_err(io(path, "tresca/times"))?;
        if times[..completed] != problem.scene.times[..completed] {
            return Err(mismatch("time grid"));
        }
        let every = int("frame_every").max(1) as usize;
        let frames = Frames { every, last: problem.n_steps() };
        let frames_done = frames.before(completed);
        let frame_list: Vec<(usize, f64)> =
            (0..completed).filter(|&n| frames.is_frame(n)).map(|n| (n, times[n])).collect();
        let mut fix = || -> hdf5::Result<StepResult> {
            // a stopped run's series were cut to its completed steps: room for the whole run again
            tresca.set_steps(&raw, problem.n_steps() + 1, completed)?;
            vtk.set_frames(&raw, frames.total(), frames_done)?;
            tresca.set_completed(completed)?;
            vtk.set_nsteps(frames_done)?;
            tresca.set_status("running (resumed)")?;
            tresca.read_step(problem, completed - 1)
        };
        let last = fix().map_err(io(path, "--resume"))?;
        let xdmf = Xdmf::resume(&file, path, &frame_list, contact, frames.total())
            .map_err(ioerr(path, "rewriting the XDMF sidecar"))?;
        file.flush().map_err(io(path, "flush"))?;
        xdmf.publish().map_err(ioerr(path, "cannot move the XDMF sidecar into place"))?;
        let w = Writer {
            path: path.to_path_buf(),
            file,
            raw,
            space: problem.space.clone(),
            fields: Fields::new(problem),
            tresca,
            vtk,
            xdmf,
            frames,
            interval: Options::default().commit_interval,
            buf: StepFields::default(),
            rows: {
                let mut r = Rows::default();
                r.reset(completed);
                r
            },
            frame_rows: {
                let mut r = FrameRows::default();
                r.reset(frames_done);
                r
            },
            frame_steps: Vec::new(),
            prev_slip: Some(last.slip.clone()),
            completed,
            frames_done,
            last_commit: Instant::now(),
            finished: false,
            pending: None,
            seconds: [0.0; 2],
        };
        Ok((w, last))
    }

    /// `--resume` with nothing to keep: the same run from step 0, in a new file.
    fn afresh(path: &Path, problem: &Problem) -> Result<(Writer, StepResult)> {
        let mut w = Writer::create_with(path, problem, &Options { force: true, ..Options::default() })?;
        let first = problem.initial()?;
        w.write_step(&first)?;
        Ok((w, first))
    }
}

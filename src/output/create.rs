//! A new results file: built under `run.h5.partial` and moved into place at its first commit (see the
//! module doc of [`super`]), on a path this run owns ([`OutputLock`]).

use super::fields::{Fields, StepFields};
use super::h5::{self, io, Raw};
use super::lock::OutputLock;
use super::paths::{self, sidecar};
use super::rows::Rows;
use super::tresca::Tresca;
use super::vtkhdf::{FrameRows, Frames, VtkHdf};
use super::xdmf::Xdmf;
use super::{ioerr, partial_path, Opened, Options, Pending, Run, Writer, AUTO_FRAMES};
use crate::error::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// The file a new one replaces, held open for reading (see [`Pending`]); not through a symbolic link,
/// and without waiting on a FIFO.
fn open_old(path: &Path) -> Option<std::fs::File> {
    use std::os::unix::fs::OpenOptionsExt;
    std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(path).ok()
}

impl Writer {
    /// Create `path` (and `run.xdmf` next to it) with mesh, static data and attributes. An existing file
    /// is refused unless `force`.
    pub fn create(path: &Path, run: &Run, force: bool) -> Result<Writer> {
        Writer::create_with(path, run, &Options { force, ..Options::default() })
    }

    /// [`Writer::create`] with all options.
    pub fn create_with(path: &Path, run: &Run, opts: &Options) -> Result<Writer> {
        Writer::create_locked(OutputLock::acquire(path)?, run, opts)
    }

    /// A new results file at `path` is refused where a directory is, and, unless `force`, where a file or
    /// its sidecar already is. [`Writer::create_locked`] checks it; a run checks it before its set-up
    /// too, since from 1,000,000 unknowns the file is created only after the factorisation.
    pub fn refuse_existing(path: &Path, force: bool) -> Result<()> {
        if path.is_dir() {
            return Err(Error::Io { path: path.to_path_buf(), msg: "is a directory, not a results file".into() });
        }
        if path.exists() && !force {
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg:
                    "results file already exists; pass --force to overwrite it or --resume to continue the run it holds"
                        .into(),
            });
        }
        let side = sidecar(path);
        if side.exists() && !force {
            return Err(Error::Io {
                path: side,
                msg: "an XDMF file exists under the name of this run's sidecar; pass --force to overwrite it".into(),
            });
        }
        Ok(())
    }

    /// [`Writer::create_with`] on the path of a lock already taken.
    pub fn create_locked(lock: OutputLock, run: &Run, opts: &Options) -> Result<Writer> {
        let path = lock.target().to_path_buf();
        let path = path.as_path();
        Writer::refuse_existing(path, opts.force)?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(ioerr(path, "cannot create the directory"))?;
        }
        // Build the file under a temporary name, renamed at its first commit (`publish`): a kill before
        // that leaves no half-made file under `path` and an old file as it was (the handles follow the rename).
        // created exclusively (O_EXCL): a name planted under `.partial` is never opened, let alone truncated
        let partial = partial_path(path);
        paths::clear_stale(&partial, "partial results file")?;
        let file = hdf5::File::with_options()
            .with_fapl(h5::file_access)
            .create_excl(&partial)
            .map_err(io(path, "cannot create HDF5 file"))?;
        let opened = Writer::fill(&file, path, &partial, run, opts).inspect_err(|_| {
            // nothing of a new file is left when it cannot be made (a full disk: the series are allocated
            // for the whole run, so the partial file would be large)
            let _ = std::fs::remove_file(&partial);
        })?;
        let (fields, tresca, vtk, xdmf, frames, raw) = opened;
        let old = paths::lstat(path)?.is_some().then(|| open_old(path)).flatten();
        let pending = Some(Pending { old, partial });
        let mut w = Writer::from_opened(path, run, fields, Opened { file, raw, tresca, vtk, xdmf, frames }, 0, None);
        w.interval = opts.commit_interval;
        w.pending = pending;
        w.lock = Some(lock);
        Ok(w)
    }

    /// The groups of a new file `file` (built at `partial`), with its sidecar started.
    #[allow(clippy::type_complexity)]
    fn fill(
        file: &hdf5::File,
        path: &Path,
        partial: &Path,
        run: &Run,
        opts: &Options,
    ) -> Result<(Fields, Tresca, VtkHdf, Xdmf, Frames, Raw)> {
        let fields = Fields::new(run);
        let contact = !run.space.contact.is_empty();
        let n = run.n_steps();
        let every = opts.frame_every.unwrap_or(n.div_ceil(AUTO_FRAMES - 1)).max(1);
        let frames = Frames { every, last: n };
        let tresca = Tresca::create(file, run).map_err(io(path, "writing the tresca group"))?;
        h5::attr(&tresca.group, "frame_every", every as i64).map_err(io(path, "attribute frame_every"))?;
        let vtk =
            VtkHdf::create(file, &fields, frames.total(), contact).map_err(io(path, "writing the VTKHDF group"))?;
        let xdmf = Xdmf::create(file, path, &fields, contact, frames.total())
            .map_err(ioerr(path, "writing the XDMF sidecar"))?;
        file.flush().map_err(io(path, "flush"))?;
        let raw = Raw::open(partial).map_err(ioerr(path, "cannot open the new file for writing"))?;
        Ok((fields, tresca, vtk, xdmf, frames, raw))
    }

    /// Record the set-up times of a file created before they were known ([`crate::Problem::new_beside`]).
    pub fn set_setup_times(&mut self, setup: &crate::stepping::SetupTimes) -> Result<()> {
        self.tresca.set_setup_times(&setup.as_array()).map_err(io(&self.path, "attribute setup_times"))
    }

    /// The writer of an open file whose first `completed` steps are committed (the last one's slip
    /// `prev_slip`), committing every step until told otherwise.
    pub(super) fn from_opened(
        path: &Path,
        run: &Run,
        fields: Fields,
        o: Opened,
        completed: usize,
        prev_slip: Option<Vec<f64>>,
    ) -> Writer {
        let frames_done = o.frames.before(completed);
        let mut rows = Rows::default();
        rows.reset(completed);
        let mut frame_rows = FrameRows::default();
        frame_rows.reset(frames_done);
        Writer {
            path: path.to_path_buf(),
            file: o.file,
            raw: o.raw,
            space: run.space.clone(),
            data: run.data.cloned(),
            fields,
            tresca: o.tresca,
            vtk: o.vtk,
            xdmf: o.xdmf,
            frames: o.frames,
            interval: Options::default().commit_interval,
            buf: StepFields::default(),
            mid: Vec::new(),
            rows,
            frame_rows,
            frame_steps: Vec::new(),
            prev_slip,
            completed,
            frames_done,
            last_commit: Instant::now(),
            finished: false,
            pending: None,
            seconds: [0.0; 2],
            lock: None,
        }
    }

    /// Move a new file and its sidecar into place (`rename`, atomic for each; the old file's blocks
    /// are freed by a background thread). Done at the first commit, so a run killed or failing before
    /// its step 0 is on disk leaves an old pair as it was and no file without a step.
    pub(super) fn publish(&mut self) -> Result<()> {
        if let Some(Pending { partial, old }) = self.pending.take() {
            std::fs::rename(&partial, &self.path).map_err(ioerr(&self.path, "cannot move the new file into place"))?;
            if let Some(old) = old {
                std::thread::spawn(move || drop(old));
            }
            self.xdmf.publish().map_err(ioerr(&self.path, "cannot move the XDMF sidecar into place"))?;
        }
        Ok(())
    }
}

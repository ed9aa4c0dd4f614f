//! A new results file: built under `run.h5.partial` and moved into place at its first commit (see the
//! module doc of [`super`]), on a path this run owns ([`OutputLock`]).

use super::fields::{Fields, StepFields};
use super::h5::{self, io, Raw};
use super::lock::OutputLock;
use super::paths::{self, sidecar};
use super::reserve;
use super::rows::Rows;
use super::tresca::Tresca;
use super::vtkhdf::{FrameRows, Frames, VtkHdf};
use super::xdmf::Xdmf;
use super::{ioerr, partial_path, Opened, Options, Pending, Run, Writer, AUTO_FRAMES};
use crate::error::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// The visualisation frames of a run of `n` steps: every `--frame-every` steps, by default at most
/// [`AUTO_FRAMES`].
fn frames_of(n: usize, opts: &Options) -> Frames {
    Frames { every: opts.frame_every.unwrap_or(n.div_ceil(AUTO_FRAMES - 1)).max(1), last: n }
}

/// What is reserved for a new file of `run` with `frames` frames before the library builds it: the
/// estimate of `scene::budget::results_file` plus the metadata of a frame (8 virtual datasets and their
/// object headers: about 13.5 KB a frame measured on an 8-triangle mesh with 2,001 frames), with an
/// eighth more, since only a reservation that covers the whole file keeps the library from a full disk.
fn file_bytes(run: &Run, frames: u64) -> u64 {
    const FRAME_METADATA: u64 = 16 << 10;
    let sizes = (run.mesh.tris.len() as u64, run.mesh.edges.len() as u64, run.space.contact.len() as u64);
    let est = crate::scene::budget::results_file(sizes, run.n_steps() as u64, frames)
        .saturating_add(frames.saturating_mul(FRAME_METADATA));
    est.saturating_add(est / 8)
}

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
        Writer::refuse_existing_for(path, force, true)
    }

    /// [`Writer::refuse_existing`] for a command that can (`resumable`, `run --resume`) or cannot
    /// (`adapt`) continue the run an existing file holds: the refusal suggests only what the command does.
    pub fn refuse_existing_for(path: &Path, force: bool, resumable: bool) -> Result<()> {
        if path.is_dir() {
            return Err(Error::Io { path: path.to_path_buf(), msg: "is a directory, not a results file".into() });
        }
        if path.exists() && !force {
            let resume = if resumable { " or --resume to continue the run it holds" } else { "" };
            return Err(Error::Io {
                path: path.to_path_buf(),
                msg: format!("results file already exists; pass --force to overwrite it{resume}"),
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
        let frames = frames_of(run.n_steps(), opts);
        let opened = Writer::reserve_new(&partial, path, run, frames)
            .and_then(|raw| Writer::fill(&file, path, run, frames, raw))
            .inspect_err(|_| {
                // nothing of a new file is left when it cannot be made (a full disk: the series are
                // allocated for the whole run, so the partial file would be large)
                let _ = std::fs::remove_file(&partial);
            })?;
        let (fields, tresca, vtk, xdmf, raw) = opened;
        let old = paths::lstat(path)?.is_some().then(|| open_old(path)).flatten();
        let pending = Some(Pending { old, partial });
        let mut w = Writer::from_opened(path, run, fields, Opened { file, raw, tresca, vtk, xdmf, frames }, 0, None);
        w.interval = opts.commit_interval;
        w.pending = pending;
        w.lock = Some(lock);
        Ok(w)
    }

    /// The plain handle on a new file (at `partial`, for `path`), with the whole estimated file reserved
    /// before the library writes into it (`reserve`).
    fn reserve_new(partial: &Path, path: &Path, run: &Run, frames: Frames) -> Result<Raw> {
        let raw = Raw::open(partial).map_err(ioerr(path, "cannot open the new file for writing"))?;
        let need = file_bytes(run, frames.total() as u64);
        reserve::from_start(&raw.0, need).map_err(|e| reserve::no_room(path, need, "for the results file", &e))?;
        Ok(raw)
    }

    /// The groups of a new file `file` (for `path`), with its sidecar started; once flushed, every byte of
    /// the file is allocated (the series of every step, `reserve`) and the rest of the reservation handed
    /// back.
    fn fill(
        file: &hdf5::File,
        path: &Path,
        run: &Run,
        frames: Frames,
        raw: Raw,
    ) -> Result<(Fields, Tresca, VtkHdf, Xdmf, Raw)> {
        let fields = Fields::new(run);
        let contact = (!run.space.contact.is_empty(), !run.space.normal_edges().is_empty());
        let tresca = Tresca::create(file, run).map_err(io(path, "writing the tresca group"))?;
        h5::attr(&tresca.group, "frame_every", frames.every as i64).map_err(io(path, "attribute frame_every"))?;
        let vtk =
            VtkHdf::create(file, &fields, frames.total(), contact).map_err(io(path, "writing the VTKHDF group"))?;
        let xdmf = Xdmf::create(file, path, &fields, contact, frames.total())
            .map_err(ioerr(path, "writing the XDMF sidecar"))?;
        file.flush().map_err(io(path, "flush"))?;
        let len = raw.0.metadata().map_err(ioerr(path, "cannot inspect the new file"))?.len();
        reserve::allocate(&raw.0).map_err(|e| reserve::no_room(path, len, "for every step of the run", &e))?;
        reserve::trim(&raw.0).map_err(ioerr(path, "cannot hand back the space reserved beyond the new file"))?;
        Ok((fields, tresca, vtk, xdmf, raw))
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
        let mut rows = Rows { rigid_width: run.rigid, ..Rows::default() };
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
                // where no thread can be started, the refused closure drops the old file here instead
                let _ = std::thread::Builder::new().spawn(move || drop(old));
            }
            self.xdmf.publish().map_err(ioerr(&self.path, "cannot move the XDMF sidecar into place"))?;
        }
        Ok(())
    }
}

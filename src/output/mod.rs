//! Results output: one HDF5 file `run.h5` holding three views of the same run, and an XDMF3 sidecar.
//!
//! | group | for | content |
//! |---|---|---|
//! | `/tresca` | the project's tools (`scripts/`) | the table of docs/results.md, f64, one row per completed step ([`tresca`]) |
//! | `/VTKHDF` | ParaView ≥ 5.13, VTK ≥ 9.4 `vtkHDFReader` | temporal PartitionedDataSetCollection: block `body` (broken mesh, 3 points per triangle) and block `contact` (Γ_C line cells), each with only its own f32 fields ([`vtkhdf`], [`fields`]) |
//! | `/xdmf` | `run.xdmf` (ParaView 5.11's XDMF readers, meshio's `TimeSeriesReader`) | static topologies and per-frame virtual datasets onto `/VTKHDF` arrays, one temporal collection per block ([`xdmf`]) |
//!
//! **What is written when.** Every step goes to `/tresca`; the VTKHDF/XDMF views get *frames*: the
//! steps n with n % `frame_every` == 0 and the last step ([`Options::frame_every`]; by default at most
//! [`AUTO_FRAMES`] frames, since each frame costs ~0.3 MB and 8 HDF5 objects).
//!
//! **Crash safety.** Steps handed to [`Writer::write_step`] are committed in batches: a batch is written
//! as soon as [`Options::commit_interval`] seconds have passed since the previous commit (default
//! 0: every step), at the last step, and by [`Writer::finish`] / drop. `tresca-cr run` hands the steps
//! to a writer thread ([`Background`]) so that the solver goes on while they are written; there a step
//! is committed as soon as the thread gets to it, together with the steps that queued up behind it
//! (at most [`background::QUEUE`] steps or `rows::BUDGET` bytes; [`Writer::write_step_then`]), and [`Background::finish`] returns
//! only when every step handed over is committed and the file closed. A commit appends the
//! batch to every time-dependent dataset (allocated for the whole run at creation, contiguous, written
//! straight to the kernel: [`h5::Series`]), then sets `tresca/steps` attribute `completed` and
//! `NSteps` of each `VTKHDF/<block>/Steps`, flushes the file (H5Fflush: only these counters are dirty
//! metadata), and only then appends the frames to `run.xdmf`. A new file is built as `run.h5.partial`
//! and `run.xdmf.partial`, both renamed into place at the first commit (a run that commits
//! nothing removes them), so a file under its name always holds at least step 0, and a run killed
//! before that leaves an old pair as it was (the two renames follow each other; only between them does
//! a new `run.h5` sit beside the old `run.xdmf`). A process killed at any moment therefore
//! leaves every committed step readable and loses at most `commit_interval` seconds of work (rows beyond
//! `completed`/`NSteps` hold no data; HDF5 has no journal, so a kill *inside* H5Fflush is the one
//! window this does not cover). A run that stops (solver failure) is finished with every series cut to
//! its completed steps. [`Writer::resume`]
//! returns the last complete step of a file; continuing from it is bit-identical to
//! an uninterrupted run because a step depends on the previous one only through its slip and μ, both
//! stored exactly. Non-finite values are refused before anything of the step is written.
//!
//! **One writer per path.** [`Writer::create_with`] and [`Writer::resume`] first take the path's
//! [`OutputLock`] (`run.h5.lock`, `flock`), before anything is opened or truncated; a second writer is
//! refused naming the process that holds it. Each committed step carries a checksum
//! (`tresca/steps/checksum`, [`tresca`]), verified by `--resume`.
//!
//! Attributes of `/tresca`: `scene` (full text), `scene_path`, `title`, `version` (crate),
//! `git_commit` (of the build, from `build.rs`), `solver`, `tol`,
//! `max_iter`, `uzawa_step`, `rho`, `E`, `nu`, `steps` (N), `n_edges`, `n_contact`, `n_dofs`,
//! `paper_dofs`, `h`, `setup_times` (4 wall times, s), `status` ("running", then what
//! [`Writer::finish`] records: "completed" or the error of the failed step).

mod background;
pub mod checksum;
mod close;
mod create;
pub mod fields;
pub mod guard;
mod h5;
mod lock;
mod normal_series;
mod paths;
mod reserve;
mod resume;
mod rigid_series;
mod rows;
mod take;
pub mod tresca;
pub mod vtkhdf;
mod vtkhdf_lists;
pub mod xdmf;

use crate::error::{Error, Result};
use crate::fem::elasticity::Elasticity;
use crate::fem::lifting::BoundaryData;
use crate::fem::space::CrSpace;
use crate::mesh::Mesh;
use crate::scene::Scene;
use crate::stepping::{Discretised, Problem, SetupTimes, StepResult};
use fields::{Fields, StepFields};
use h5::{io, Raw};
use rows::Rows;
use std::path::{Path, PathBuf};
use std::time::Instant;
use tresca::Tresca;
use vtkhdf::{FrameRows, Frames, VtkHdf};
use xdmf::Xdmf;

pub use background::Background;
pub use lock::{lock_path, OutputLock};
pub use paths::sidecar;
pub use paths::{check_target, check_writable};
pub use take::Unknowns;

/// Default upper bound on the number of visualisation frames.
pub const AUTO_FRAMES: usize = 51;

/// How a [`Writer`] is created.
#[derive(Clone, Debug)]
pub struct Options {
    /// Overwrite an existing file.
    pub force: bool,
    /// Visualisation frame every k steps (plus the last step); `None`: ⌈N / (AUTO_FRAMES − 1)⌉.
    pub frame_every: Option<usize>,
    /// Seconds between commits (write + flush); 0 commits every step (on a writer thread: every step
    /// together with those queued behind it, see [`Background`]).
    pub commit_interval: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options { force: false, frame_every: None, commit_interval: 0.0 }
    }
}

/// What a results file records about a run besides its steps.
#[derive(Clone, Copy, Debug)]
pub struct RunMeta {
    /// Crate version.
    pub version: &'static str,
    /// Git commit of the build (`build.rs`; "-dirty" when the tree had changes).
    pub commit: &'static str,
    pub setup: SetupTimes,
    /// True errors are computed (the scene gives `[exact]`).
    pub true_errors: bool,
}

/// What the writer needs of a run: the discretisation it writes (scene with the solver settings in
/// force, mesh, space, law) and the run's metadata.
#[derive(Clone, Copy)]
pub struct Run<'a> {
    pub scene: &'a Scene,
    pub mesh: &'a Mesh,
    pub space: &'a CrSpace,
    /// The boundary data whose lifting the written displacement includes.
    pub data: Option<&'a BoundaryData>,
    pub law: Elasticity,
    pub meta: RunMeta,
    /// The number of rigid motions of a floating body (`solve::kernel`; 0 when a Dirichlet part fixes
    /// them): the width of `tresca/rigid`, α of every step, for the warm start of `--resume`.
    pub rigid: usize,
}

impl<'a> Run<'a> {
    /// The run of `p` with this build's version and commit.
    pub fn of(p: &'a Problem) -> Run<'a> {
        let rigid = p.free.kernel().map_or(0, |k| k.r.ncols());
        Run::new(&p.scene, &p.mesh, (&p.space, p.data.as_ref()), p.law, (p.setup, rigid))
    }

    /// The run of a problem whose set-up is still under way ([`Problem::new_beside`]): its set-up times
    /// are zeros until [`Writer::set_setup_times`].
    pub fn before_setup(p: &'a Discretised) -> Run<'a> {
        let rigid = p.kernel.as_ref().map_or(0, |k| k.r.ncols());
        Run::new(&p.scene, &p.mesh, (&p.space, p.data.as_ref()), p.law, (SetupTimes::default(), rigid))
    }

    /// With this build's version and commit; true errors are computed when the scene gives `[exact]`.
    fn new(
        scene: &'a Scene,
        mesh: &'a Mesh,
        (space, data): (&'a CrSpace, Option<&'a BoundaryData>),
        law: Elasticity,
        (setup, rigid): (SetupTimes, usize),
    ) -> Run<'a> {
        let meta = RunMeta {
            version: env!("CARGO_PKG_VERSION"),
            commit: env!("TRESCA_BUILD_COMMIT"),
            setup,
            true_errors: scene.exact.is_some(),
        };
        Run { scene, mesh, space, data, law, meta, rigid }
    }

    /// Number of time steps N.
    pub fn n_steps(&self) -> usize {
        self.scene.times.len() - 1
    }
}

/// The open parts of a results file, new or resumed.
struct Opened {
    file: hdf5::File,
    raw: Raw,
    tresca: Tresca,
    vtk: VtkHdf,
    xdmf: Xdmf,
    frames: Frames,
}

/// Appends the steps of a run to a results file.
pub struct Writer {
    path: PathBuf,
    file: hdf5::File,
    /// Plain handle for the direct writes of the series ([`h5::Series`]).
    raw: Raw,
    space: CrSpace,
    data: Option<BoundaryData>,
    fields: Fields,
    tresca: Tresca,
    vtk: VtkHdf,
    xdmf: Xdmf,
    frames: Frames,
    interval: f64,
    buf: StepFields,
    /// Midpoint values of the step being taken (memory reused from step to step).
    mid: Vec<[f64; 2]>,
    rows: Rows,
    frame_rows: FrameRows,
    /// Step numbers of the buffered frames.
    frame_steps: Vec<usize>,
    prev_slip: Option<Vec<f64>>,
    /// Committed steps and frames.
    completed: usize,
    frames_done: usize,
    last_commit: Instant,
    finished: bool,
    /// A new file still under `run.h5.partial`: moved into place at its first commit ([`Writer::publish`]).
    pending: Option<Pending>,
    /// Seconds spent in write_step (all of it) and in H5Fflush alone.
    pub seconds: [f64; 2],
    /// The exclusive ownership of the path ([`OutputLock`]); last, so it is released after the file closes.
    lock: Option<OutputLock>,
}

/// A created file not yet under its name, and the old file it will replace (held open so its blocks are
/// freed by a background thread, not by the rename).
struct Pending {
    partial: PathBuf,
    old: Option<std::fs::File>,
}

/// `path` with `.partial` appended: where a new file (or sidecar) is built before it is moved into place.
fn partial_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".partial");
    PathBuf::from(s)
}

fn ioerr(path: &Path, what: &'static str) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.to_path_buf();
    move |e| Error::Io { path, msg: format!("{what}: {e}") }
}

impl Writer {
    /// Number of steps committed to the file.
    pub fn completed(&self) -> usize {
        self.completed
    }

    /// The results file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Seconds between commits (0: every step).
    pub fn set_commit_interval(&mut self, seconds: f64) {
        self.interval = seconds;
    }

    /// Take step `r` (the step after the last one taken): checked for non-finite values, buffered, and
    /// committed (see the module doc) once the commit interval has passed or at the last step.
    pub fn write_step(&mut self, r: &StepResult) -> Result<()> {
        self.write_step_then(r, false)
    }

    /// Steps taken but not committed yet.
    pub fn buffered(&self) -> usize {
        self.rows.count
    }

    /// [`Writer::write_step`], but with `more` (another step is at hand, see [`Background`]) the commit
    /// waits for it: it is then made once the commit interval has passed *and* either no further step is
    /// at hand or [`background::QUEUE`] steps are buffered, and always at the last step.
    pub fn write_step_then(&mut self, r: &StepResult, more: bool) -> Result<()> {
        let start = Instant::now();
        let u = Unknowns::of(&self.path, (&self.space, self.data.as_ref()), r, std::mem::take(&mut self.mid));
        self.seconds[0] += start.elapsed().as_secs_f64();
        self.write_unknowns(u, more)
    }

    /// [`Writer::write_step_then`] of a step whose unknowns were evaluated already ([`Unknowns::of`]).
    pub fn write_unknowns(&mut self, u: Result<Unknowns>, more: bool) -> Result<()> {
        let start = Instant::now();
        let out = u.and_then(|u| {
            let n = u.n();
            self.take(u).map(|()| n)
        });
        let due = self.last_commit.elapsed().as_secs_f64() >= self.interval
            && (!more
                || self.rows.count >= background::QUEUE
                || self.rows.bytes() + self.frame_rows.bytes() >= rows::BUDGET);
        let out = match out {
            Ok(n) if due || n == self.frames.last => self.commit(),
            Ok(_) => Ok(()),
            Err(e) => {
                // keep what was good
                let _ = self.commit();
                Err(e)
            }
        };
        self.seconds[0] += start.elapsed().as_secs_f64();
        out
    }

    /// Write the buffered steps, mark them complete, flush, extend the XDMF text.
    pub fn commit(&mut self) -> Result<()> {
        if self.rows.count == 0 {
            return Ok(());
        }
        let path = self.path.clone();
        let (steps, nf) = (self.completed + self.rows.count, self.frames_done + self.frame_rows.count());
        if nf > self.frames_done {
            // the one commit that allocates in the file (a chunk of `Steps/Values`): its room first
            reserve::ahead(&self.raw.0, reserve::MARGIN).map_err(|e| {
                let what = format!("to commit steps {}..{}", self.completed, steps - 1);
                reserve::no_room(&path, reserve::MARGIN, &what, &e)
            })?;
        }
        let write = || -> hdf5::Result<()> {
            self.tresca.write_rows(&self.raw, &self.rows)?;
            self.vtk.write_frames(&self.raw, &self.frame_rows)
        };
        write().map_err(io(&path, &format!("writing steps {}..{}", self.completed, steps - 1)))?;
        // The series data is in the kernel now (direct writes, see `h5::Series`), so the counters that
        // declare it complete may follow in one flush. Each block's `Steps/Values` grows in that same flush: it
        // must never be longer than `NSteps` (see `vtkhdf::VtkHdf`).
        let f0 = Instant::now();
        let mark = || -> hdf5::Result<()> {
            self.vtk.set_nsteps(nf)?;
            self.tresca.set_completed(steps)
        };
        mark().map_err(io(&path, "marking the steps complete"))?;
        self.file.flush().map_err(io(&path, "flush"))?;
        self.seconds[1] += f0.elapsed().as_secs_f64();
        // the steps are in the file: the writer counts them before the sidecar is written, so a sidecar
        // that cannot be written (a full disk) loses none of them
        let first_frame = self.frames_done;
        let new_frames: Vec<(usize, f64)> =
            self.frame_steps.iter().zip(&self.frame_rows.times).map(|(&n, &t)| (n, t)).collect();
        self.completed = steps;
        self.frames_done = nf;
        self.rows.reset(steps);
        self.frame_rows.reset(nf);
        self.frame_steps.clear();
        self.last_commit = Instant::now();
        for (k, &(n, t)) in new_frames.iter().enumerate() {
            self.xdmf
                .append_text(first_frame + k, n, t)
                .map_err(ioerr(&self.xdmf.path.clone(), "appending to the XDMF sidecar"))?;
        }
        if !new_frames.is_empty() {
            self.xdmf.write_text().map_err(ioerr(&self.xdmf.path.clone(), "writing the XDMF sidecar"))?;
        }
        self.publish()
    }
}

//! [`Background`]: a [`Writer`] on a thread of its own, so that the solver computes the next steps while
//! the committed ones are written (the process has two cores; writing Example 5.1's 640 steps takes
//! about three times as long as solving them).
//!
//! Steps go to the writer thread through a bounded queue of [`QUEUE`] steps; the caller's thread checks
//! each step's u and evaluates what is written of it ([`Unknowns`], the larger half of taking a step,
//! done there so that both threads share the work), the writer thread takes, commits and finishes them
//! exactly as a [`Writer`] on the caller's thread would, so the file and its crash safety (see the module
//! doc of [`super`]) are the same. What changes is *when* an error is seen: a non-finite u is refused at
//! once, but a step the writer thread refuses or fails to write (another non-finite value, a full disk)
//! is reported by a later [`Background::write_step`] (so the solver stops a few steps after it) or, at the
//! latest, by [`Background::finish`], which returns only once every step it was handed is committed and
//! the file is closed. The file records the first error as its `status` ("stopped: …"), whatever status
//! the caller gives, and every step handed over after it is ignored: a run that failed to write never
//! ends as "completed" or with a gap.

use super::{Unknowns, Writer};
use crate::error::{Error, Result};
use crate::fem::lifting::BoundaryData;
use crate::fem::space::CrSpace;
use crate::stepping::StepResult;
use std::sync::mpsc::{sync_channel, Receiver, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;

/// Steps queued for the writer thread at most: two blocks of the solver (`solve::free`'s blocks of up to
/// 16 steps are handed over at once), so the solver rarely waits, while the queue holds at most a few MB.
pub const QUEUE: usize = 32;

enum Msg {
    Step(Box<Unknowns>),
    Finish(String),
}

/// The first error of the writer thread, until the caller has been told of it.
#[derive(Default)]
struct Failure {
    error: Option<Error>,
    /// The thread failed (the error may already have been handed to the caller).
    failed: bool,
}

/// A [`Writer`] running on its own thread (see the module doc).
pub struct Background {
    tx: Option<SyncSender<Msg>>,
    thread: Option<JoinHandle<Result<usize>>>,
    failure: Arc<Mutex<Failure>>,
    path: std::path::PathBuf,
    /// The writer's space and boundary data: the caller's thread evaluates [`Unknowns`] with them.
    space: CrSpace,
    data: Option<BoundaryData>,
    /// The status of a run whose step this thread refused (a non-finite u): what the file records.
    refused: Option<String>,
}

/// The writer thread: take steps until told to finish; after the first error, ignore the steps.
fn serve(mut w: Writer, rx: Receiver<Msg>, failure: Arc<Mutex<Failure>>) -> Result<usize> {
    let mut stopped: Option<String> = None;
    let mut next = rx.recv().ok();
    while let Some(msg) = next.take() {
        match msg {
            Msg::Step(r) => {
                // a step already queued behind this one: commit them together (group commit)
                next = rx.try_recv().ok();
                let more = matches!(next, Some(Msg::Step(_)));
                if stopped.is_none() {
                    if let Err(e) = w.write_unknowns(Ok(*r), more) {
                        stopped = Some(format!("stopped: {e}"));
                        if let Ok(mut f) = failure.lock() {
                            *f = Failure { error: Some(e), failed: true };
                        }
                    }
                }
                if next.is_none() {
                    next = rx.recv().ok();
                }
            }
            Msg::Finish(status) => return w.finish(stopped.as_deref().unwrap_or(&status)),
        }
    }
    // the caller went away without finishing (a panic): the writer's drop closes the file as a stopped run
    Ok(0)
}

impl Background {
    /// Move `w` to a new thread.
    pub fn spawn(w: Writer) -> Result<Background> {
        let (tx, rx) = sync_channel(QUEUE);
        let failure = Arc::new(Mutex::new(Failure::default()));
        let f = Arc::clone(&failure);
        let (path, space, data) = (w.path().to_path_buf(), w.space.clone(), w.data.clone());
        let thread = std::thread::Builder::new()
            .name("writer".into())
            .spawn(move || serve(w, rx, f))
            .map_err(|e| Error::Io { path: path.clone(), msg: format!("cannot start the writer thread: {e}") })?;
        Ok(Background { tx: Some(tx), thread: Some(thread), failure, path, space, data, refused: None })
    }

    /// The writer's first error if the caller has not been told of it yet.
    fn take_error(&self) -> Option<Error> {
        self.failure.lock().ok().and_then(|mut f| f.error.take())
    }

    /// Check u of step `r` and hand the step to the writer thread (waiting while [`QUEUE`] steps are
    /// queued). An error of an earlier step is returned here, once.
    pub fn write_step(&mut self, r: &StepResult) -> Result<()> {
        if let Some(e) = self.take_error() {
            return Err(e);
        }
        if self.failure.lock().map_or(true, |f| f.failed) {
            // told already: the steps after a failed one are not written
            return Ok(());
        }
        let u = match Unknowns::of(&self.path, (&self.space, self.data.as_ref()), r, Vec::new()) {
            Ok(u) => u,
            Err(e) => {
                if let Ok(mut f) = self.failure.lock() {
                    f.failed = true;
                }
                self.refused = Some(format!("stopped: {e}"));
                return Err(e);
            }
        };
        match &self.tx {
            Some(tx) if tx.send(Msg::Step(Box::new(u))).is_ok() => Ok(()),
            _ => Err(self.take_error().unwrap_or_else(|| self.gone())),
        }
    }

    fn gone(&self) -> Error {
        Error::Io { path: self.path.clone(), msg: "the writer thread stopped unexpectedly".into() }
    }

    /// Commit every step handed over, record `status` (unless a write failed: then its error) and close
    /// the file; returns the number of steps in the file. A write error the caller was not told of yet is
    /// returned here (after the file is closed).
    pub fn finish(mut self, status: &str) -> Result<usize> {
        let status = self.refused.take().unwrap_or_else(|| status.to_string());
        let sent = self.tx.take().is_some_and(|tx| tx.send(Msg::Finish(status)).is_ok());
        let joined = self.thread.take().map(|t| t.join());
        let done = match joined {
            Some(Ok(r)) if sent => r,
            Some(Ok(Err(e))) => Err(e),
            _ => Err(self.gone()),
        };
        match self.take_error() {
            Some(e) => Err(e),
            None => done,
        }
    }
}

impl Drop for Background {
    /// Dropped without [`Background::finish`] (an error or a panic of the caller): the queued steps are
    /// committed and the file closed as a stopped run before the drop returns.
    fn drop(&mut self) {
        self.tx.take();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

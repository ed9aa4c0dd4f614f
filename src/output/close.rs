//! The end of a results file: the last commit, the status, and for a run that stopped early its series
//! cut to the completed steps — only when the room to cut them is reserved (`super::reserve`): a file
//! that cannot be cut is left at full length, whose rows beyond `completed` hold no data, as a killed
//! run leaves it.

use super::h5::io;
use super::{reserve, Pending, Writer};
use crate::error::Result;

impl Writer {
    /// Commit what is buffered, record why the run stopped ("completed", or the error of the failed
    /// step) and close the file. A run that stopped early has its series cut to the completed steps.
    /// Returns the number of steps in the file (0: no file was written, see [`Writer::publish`]).
    pub fn finish(mut self, status: &str) -> Result<usize> {
        self.close(status)?;
        Ok(self.completed)
    }

    pub(super) fn close(&mut self, status: &str) -> Result<()> {
        // a last commit that fails (a full disk) does not end the closing: the file still records why it
        // stopped, and a file without a step is removed
        let committed = self.commit();
        self.finished = true;
        if self.completed == 0 {
            // nothing committed (the run failed at step 0): no results file replaces an old one
            if let Some(Pending { partial, .. }) = self.pending.take() {
                let _ = std::fs::remove_file(partial);
                self.xdmf.discard();
            }
            return committed;
        }
        let status = match &committed {
            Err(e) if !status.starts_with("stopped") => format!("stopped: {e}"),
            _ => status.to_string(),
        };
        let all = self.frames.last + 1;
        let ended = if self.completed < all || committed.is_err() {
            let cut = self.cut(&status);
            committed.and(cut)
        } else {
            self.mark(&status)
        };
        // what was reserved beyond the end is handed back (the file is complete as it stands)
        let _ = reserve::trim(&self.raw.0);
        ended.and(self.publish())
    }

    /// Record `status` and flush, with the room for it reserved first (without it the status stays
    /// "running", the state of a killed run).
    fn mark(&mut self, status: &str) -> Result<()> {
        let path = self.path.clone();
        reserve::ahead(&self.raw.0, reserve::MARGIN)
            .map_err(|e| reserve::no_room(&path, reserve::MARGIN, "to record the run's status", &e))?;
        self.tresca.set_status(status).map_err(io(&path, "attribute status"))?;
        self.file.flush().map_err(io(&path, "flush"))
    }

    /// A stopped run: series of exactly the completed steps, so no reader meets unwritten rows — if the
    /// room to rewrite them is reserved; else they are left at full length and the status says so.
    fn cut(&mut self, status: &str) -> Result<()> {
        let path = self.path.clone();
        let (steps, frames, all) = (self.completed, self.frames_done, self.frames.last + 1);
        let len = self.raw.0.metadata().map_or(0, |m| m.len());
        // the rewritten series hold the completed share of the file's rows
        let room = (len as u128 * steps as u128 / all as u128) as u64 + reserve::MARGIN;
        if let Err(e) = reserve::ahead(&self.raw.0, room) {
            let why = reserve::no_room(&path, room, "to cut the series to the completed steps", &e);
            return self.mark(&format!("{status}; left at full length, rows beyond `completed` hold no data ({why})"));
        }
        let mut shrink = || -> hdf5::Result<()> {
            self.tresca.set_steps(&self.raw, steps, steps)?;
            self.vtk.set_frames(&self.raw, frames, frames)?;
            self.xdmf.drop_frames_from(frames)
        };
        let shrunk = shrink().map_err(io(&path, "shrinking the series of a stopped run"));
        let marked = self.tresca.set_status(status).map_err(io(&path, "attribute status"));
        let flushed = self.file.flush().map_err(io(&path, "flush"));
        shrunk.and(marked).and(flushed)
    }
}

impl Drop for Writer {
    /// A writer dropped without [`Writer::finish`] (an error, a panic) still commits what it holds and
    /// closes the file as a stopped run.
    fn drop(&mut self) {
        if !self.finished {
            let _ = self.close("stopped: the writer was dropped before the run finished");
        }
    }
}

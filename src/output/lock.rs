//! One run per results file. A run owns its output path `run.h5` through an exclusive `flock` on
//! `run.h5.lock`, taken before anything of the output is opened, created or truncated (the `.partial`
//! files, the sidecar, an old file under `--resume`) and released when the writer is dropped (the lock
//! file is removed) or when the process ends in any way, including SIGKILL: the kernel drops the locks of
//! a dead process, so a lock file left by a killed run is stale and simply taken over. A second run on
//! the same path is refused at once, naming the process that holds it. The lock does not depend on
//! HDF5's own file locking (which `HDF5_USE_FILE_LOCKING=FALSE` turns off).

use crate::error::{Error, Result};
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::MetadataExt;
use std::os::unix::io::AsRawFd;
use std::path::{Path, PathBuf};

/// The exclusive ownership of a results path (see the module doc). Dropping it releases the path.
#[derive(Debug)]
pub struct OutputLock {
    /// The results file this lock guards.
    target: PathBuf,
    /// `target` + `.lock`.
    lock_path: PathBuf,
    file: File,
}

/// `path` with `.lock` appended.
pub fn lock_path(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".lock");
    PathBuf::from(s)
}

impl OutputLock {
    /// Take the results path `target` for this process, or refuse naming the process that has it.
    /// Creates the missing directories of `target`.
    pub fn acquire(target: &Path) -> Result<OutputLock> {
        let lock_path = lock_path(target);
        let err = |msg: String| Error::Io { path: target.to_path_buf(), msg };
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create the directory: {e}")))?;
        }
        loop {
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&lock_path)
                .map_err(|e| err(format!("cannot create the lock file {}: {e}", lock_path.display())))?;
            // SAFETY: flock on a file descriptor this function owns; no memory is passed.
            if unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) } != 0 {
                let e = std::io::Error::last_os_error();
                if e.raw_os_error() == Some(libc::EWOULDBLOCK) {
                    let mut holder = String::new();
                    let _ = file.read_to_string(&mut holder);
                    let holder = holder.trim();
                    let who =
                        if holder.is_empty() { "another process".to_string() } else { format!("process {holder}") };
                    return Err(Error::Busy { path: target.to_path_buf(), holder: who });
                }
                return Err(err(format!("cannot lock {}: {e}", lock_path.display())));
            }
            // A holder removes the lock file before it unlocks it: the file locked here must still be the
            // one under the name, else another run may lock a new one; take it again.
            let same = match (file.metadata(), std::fs::metadata(&lock_path)) {
                (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
                _ => false,
            };
            if !same {
                continue;
            }
            let mut record = || -> std::io::Result<()> {
                file.set_len(0)?;
                file.rewind()?;
                let exe = std::env::args().next().unwrap_or_default();
                write!(file, "{} ({exe})", std::process::id())?;
                file.flush()
            };
            record().map_err(|e| err(format!("cannot write the lock file {}: {e}", lock_path.display())))?;
            return Ok(OutputLock { target: target.to_path_buf(), lock_path, file });
        }
    }

    /// The results file this lock guards.
    pub fn target(&self) -> &Path {
        &self.target
    }
}

impl Drop for OutputLock {
    /// Remove the lock file, then unlock it (closing the descriptor).
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.lock_path);
        let _ = &self.file;
    }
}

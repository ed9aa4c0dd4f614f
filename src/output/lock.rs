//! One run per results file. A run owns its output path `run.h5` through an exclusive `flock` on
//! `run.h5.lock`, taken before anything of the output is opened, created or truncated (the `.partial`
//! files, the sidecar, an old file under `--resume`) and released when the writer is dropped (the lock
//! file is removed) or when the process ends in any way, including SIGKILL: the kernel drops the locks of
//! a dead process, so a lock file left by a killed run is stale and simply taken over. A second run on
//! the same path is refused at once, naming the process that holds it. The lock file is created with
//! `O_EXCL` (see [`super::paths`]); a stale one is removed while held, never truncated. The lock does not depend on
//! HDF5's own file locking (which `HDF5_USE_FILE_LOCKING=FALSE` turns off).

use crate::error::{Error, Result};
use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
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
        super::paths::check_target(target, false)?;
        if let Some(dir) = target.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| err(format!("cannot create the directory: {e}")))?;
        }
        loop {
            // the lock file is this run's own (O_EXCL); one that exists is opened only to see whether a
            // live run holds it, never truncated or written
            let (mut file, created) = match super::paths::create_new(&lock_path) {
                Ok(f) => (f, true),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => match open_existing(&lock_path)? {
                    Some(f) => (f, false),
                    None => continue, // removed meanwhile
                },
                Err(e) => return Err(err(format!("cannot create the lock file {}: {e}", lock_path.display()))),
            };
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
            let same = match (file.metadata(), std::fs::symlink_metadata(&lock_path)) {
                (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
                _ => false,
            };
            if !same {
                continue;
            }
            if !created {
                // the lock of a run that ended without removing it (killed): remove it while holding it,
                // then create this run's own
                std::fs::remove_file(&lock_path)
                    .map_err(|e| err(format!("cannot remove the stale lock file {}: {e}", lock_path.display())))?;
                continue;
            }
            let mut record = || -> std::io::Result<()> {
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

/// Open an existing lock file to test its lock: refused unless it is a regular file with one link (a
/// symbolic link, a hard link to another file, a device or a FIFO planted under the name); `None` when
/// it disappeared meanwhile.
fn open_existing(lock_path: &Path) -> Result<Option<File>> {
    let refuse = |msg: String| Error::Io { path: lock_path.to_path_buf(), msg };
    let opened = OpenOptions::new().read(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(lock_path);
    let file = match opened {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return Err(refuse("the lock file's name is a symbolic link (not one this program made); remove it".into()))
        }
        Err(e) => return Err(refuse(format!("cannot open the lock file: {e}"))),
    };
    let m = file.metadata().map_err(|e| refuse(format!("cannot inspect the lock file: {e}")))?;
    if !m.file_type().is_file() || m.nlink() != 1 {
        return Err(refuse(format!(
            "the lock file's name is {} with {} link(s) (not one this program made); remove it",
            crate::input::kind_of(m.file_type()),
            m.nlink()
        )));
    }
    Ok(Some(file))
}

impl Drop for OutputLock {
    /// Remove the lock file, then unlock it (closing the descriptor).
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.lock_path);
        let _ = &self.file;
    }
}

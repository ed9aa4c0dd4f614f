//! The names a run writes, checked before anything is written to them: `run.h5`, its sidecar `run.xdmf`,
//! the lock `run.h5.lock` and the `.partial` files. A run creates each file it writes itself, with
//! `O_CREAT | O_EXCL` (so a name that exists, a symbolic link included, is never opened for writing), after
//! removing what a killed run left under the name: only a regular file with a single link, which no
//! other name shares. It never opens an existing file with truncation, so a link planted under one of
//! these names cannot make it overwrite another file. A results path or sidecar that is a symbolic link, a
//! device, a FIFO, a socket or a directory is refused naming what it is (a rename would otherwise replace
//! a device node such as `/dev/null` under `--force`); an existing file is replaced only by a rename,
//! which leaves any other link to it as it was.

use crate::error::{Error, Result};
use crate::input::kind_of;
use std::fs::{File, Metadata, OpenOptions};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

pub(super) fn refuse(path: &Path, msg: String) -> Error {
    Error::Io { path: path.to_path_buf(), msg }
}

/// What is under `path` itself (a final symbolic link not followed); `None` when nothing is.
pub(super) fn lstat(path: &Path) -> Result<Option<Metadata>> {
    match std::fs::symlink_metadata(path) {
        Ok(m) => Ok(Some(m)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(refuse(path, format!("cannot inspect the path: {e}"))),
    }
}

/// The XDMF path of a results file: same stem, extension `xdmf`.
pub fn sidecar(h5: &Path) -> PathBuf {
    h5.with_extension("xdmf")
}

/// Refuse a results path (or its sidecar) that is not a regular file, or that names the sidecar itself.
/// `in_place`: the run writes into the existing file (`--resume`), so a file with other links is refused
/// too (the write would change what the other names show).
pub fn check_target(target: &Path, in_place: bool) -> Result<()> {
    let side = sidecar(target);
    if side == target {
        return Err(refuse(
            target,
            format!(
                "a results file cannot end in .xdmf: its XDMF sidecar takes that name; give the HDF5 file, e.g. -o {}",
                target.with_extension("h5").display()
            ),
        ));
    }
    for (p, what) in [(target, "results file"), (side.as_path(), "XDMF sidecar of the results file")] {
        let Some(m) = lstat(p)? else { continue };
        let t = m.file_type();
        if !t.is_file() {
            let hint = if t.is_symlink() { "; give the path the link points to, or remove the link" } else { "" };
            return Err(refuse(
                p,
                format!("the {what} would go here, but the path is {} (not a regular file){hint}", kind_of(t)),
            ));
        }
        if in_place && p == target && m.nlink() > 1 {
            return Err(refuse(
                p,
                format!(
                    "the results file has {} hard links; --resume writes into it, which would change the other \
                     names too; copy it first or run afresh with --force",
                    m.nlink()
                ),
            ));
        }
    }
    Ok(())
}

/// Remove the file a killed run left at `path` (`what` names it), so that it can be created afresh: a
/// regular file with one link. Anything else there is refused, naming what it is.
pub(super) fn clear_stale(path: &Path, what: &str) -> Result<()> {
    let Some(m) = lstat(path)? else { return Ok(()) };
    let t = m.file_type();
    if !t.is_file() {
        return Err(refuse(
            path,
            format!(
                "the {what} of this run would be created here, but the path is {} (not one this program left); \
                 remove it",
                kind_of(t)
            ),
        ));
    }
    if m.nlink() > 1 {
        return Err(refuse(
            path,
            format!(
                "the {what} of this run would be created here, but the file there has {} hard links (not one \
                 this program left); remove it",
                m.nlink()
            ),
        ));
    }
    std::fs::remove_file(path).map_err(|e| refuse(path, format!("cannot remove the stale {what}: {e}")))
}

/// Create `path` as a new file (`O_CREAT | O_EXCL | O_NOFOLLOW`), readable and writable.
pub(super) fn create_new(path: &Path) -> std::io::Result<File> {
    OpenOptions::new().read(true).write(true).create_new(true).custom_flags(libc::O_NOFOLLOW).mode(0o644).open(path)
}

/// Open an existing regular file with a single link for writing, without following a symbolic link and
/// without truncating it.
pub(super) fn open_own(path: &Path) -> std::io::Result<File> {
    let f = OpenOptions::new().write(true).custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK).open(path)?;
    let m = f.metadata()?;
    if !m.file_type().is_file() || m.nlink() != 1 {
        return Err(std::io::Error::other(format!(
            "{} is {} with {} links, not the file this run made",
            path.display(),
            kind_of(m.file_type()),
            m.nlink()
        )));
    }
    Ok(f)
}

/// Refuse a results file in a directory this process cannot write (`/proc/self`, a read-only mount):
/// checked before the run's estimates, whose free space of such a file system (0 B) would say nothing
/// of the cause. The nearest existing ancestor counts for directories still to be created.
pub fn check_writable(target: &Path) -> Result<()> {
    use std::os::unix::ffi::OsStrExt;
    let mut d = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    while lstat(d)?.is_none() {
        d = d.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    }
    if !d.is_dir() {
        return Err(refuse(target, format!("cannot create the results file: {} is not a directory", d.display())));
    }
    let c = std::ffi::CString::new(d.as_os_str().as_bytes()).map_err(|e| refuse(target, e.to_string()))?;
    // SAFETY: `c` is a NUL-terminated path; access reads nothing else.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } != 0 {
        let e = std::io::Error::last_os_error();
        return Err(refuse(target, format!("cannot create the results file in {}: {e}", d.display())));
    }
    Ok(())
}

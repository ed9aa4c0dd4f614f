//! Disk space held for a results file before anything is written into it, so that a full disk is met by
//! this crate's own checks, never by a write of the HDF5 library.
//!
//! Why: HDF5 has no way back from a failed write. A metadata write that fails with ENOSPC while a dataset
//! is closed (`evict_on_close`, or the small metadata cache making room) leaves that dataset's identifier
//! without its object, and closing the file then dereferences it (SIGSEGV in `H5D__flush_all_cb`, met by
//! `adapt` on a full disk); a write of the series that fails half-way leaves a file whose counters and
//! checksums disagree with its rows.
//!
//! The mechanism: space is *reserved* (`fallocate`) before each phase that may allocate space in the
//! file, and a reservation that fails stops the phase before the library is called.
//! - creation: the whole estimated file is reserved beyond its end (`FALLOC_FL_KEEP_SIZE`, the size
//!   the library sees does not change) before the library builds it; once built, every byte up to its end
//!   (the series of every step of the run, which the library allocates but does not write) is allocated
//!   ([`allocate`]), so no step's write can meet a full disk;
//! - a commit that adds frames (the only commit that allocates: a chunk of `Steps/Values`) reserves
//!   [`MARGIN`] beyond the end first;
//! - closing a stopped run reserves the room to cut its series to the completed steps, and does not cut
//!   them if it cannot (the file is then left at full length, as a killed run leaves it);
//! - `--resume` reserves the room to give the series back their full length.
//!
//! What is reserved beyond the end and not used is handed back when the file is closed ([`trim`]).
//! Where the file system cannot reserve (`EOPNOTSUPP`), nothing is held and writes meet the disk as
//! they are.

use std::fs::File;
use std::os::unix::io::AsRawFd;

/// Bytes reserved beyond the end of the file before a commit or a change of metadata: a chunk of
/// `Steps/Values` (1024 f64) per block, its index node and the metadata a flush rewrites, with room.
pub const MARGIN: u64 = 256 << 10;

fn fallocate(file: &File, mode: libc::c_int, offset: u64, len: u64) -> std::io::Result<()> {
    if len == 0 {
        return Ok(());
    }
    let (off, len) = (i64::try_from(offset), i64::try_from(len));
    let (Ok(off), Ok(len)) = (off, len) else {
        return Err(std::io::Error::from_raw_os_error(libc::EFBIG));
    };
    loop {
        // SAFETY: fallocate only reads the descriptor and the three integers.
        let rc = unsafe { libc::fallocate(file.as_raw_fd(), mode, off, len) };
        if rc == 0 {
            return Ok(());
        }
        let e = std::io::Error::last_os_error();
        match e.raw_os_error() {
            Some(libc::EINTR) => continue,
            // the file system cannot reserve: nothing is held (module doc)
            Some(libc::EOPNOTSUPP) | Some(libc::ENOSYS) => return Ok(()),
            _ => return Err(e),
        }
    }
}

/// Reserve `bytes` beyond the end of `file` without changing its size.
pub fn ahead(file: &File, bytes: u64) -> std::io::Result<()> {
    let len = file.metadata()?.len();
    fallocate(file, libc::FALLOC_FL_KEEP_SIZE, len, bytes)
}

/// Reserve from the start of `file` up to `bytes` without changing its size (a file still to be built).
pub fn from_start(file: &File, bytes: u64) -> std::io::Result<()> {
    fallocate(file, libc::FALLOC_FL_KEEP_SIZE, 0, bytes)
}

/// Allocate every byte of `file` up to its end (the holes of the series allocated but not yet written).
pub fn allocate(file: &File) -> std::io::Result<()> {
    let len = file.metadata()?.len();
    fallocate(file, 0, 0, len)
}

/// Hand back what is reserved beyond the end of `file`: its size is raised by one byte and set back, a
/// truncation that frees every block past the end (a truncation to the same size frees nothing on tmpfs).
pub fn trim(file: &File) -> std::io::Result<()> {
    let len = file.metadata()?.len();
    file.set_len(len + 1)?;
    file.set_len(len)
}

/// The error of a reservation of `need` bytes (`what` they are for) that failed for the results file `path`.
pub fn no_room(path: &std::path::Path, need: u64, what: &str, e: &std::io::Error) -> crate::error::Error {
    let msg = if e.raw_os_error() == Some(libc::ENOSPC) {
        format!(
            "no room on the disk {what} (about {} held before writing, so that nothing written is lost): {e}",
            crate::error::human(need)
        )
    } else {
        format!("cannot reserve disk space {what} ({}): {e}", crate::error::human(need))
    };
    crate::error::Error::Io { path: path.to_path_buf(), msg }
}

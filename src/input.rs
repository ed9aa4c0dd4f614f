//! Reading the input files (scene, Gmsh mesh): only regular files, and at most [`MAX_INPUT_BYTES`] of
//! them. A path such as `/dev/zero` would otherwise be read forever and a FIFO would block the run until a
//! writer appears; both are refused naming what the path is.

use crate::error::{Error, Result};
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;

/// Largest input file read (bytes). The largest mesh the budget lets this machine solve (24 GiB: about
/// 6 million unknowns, 2 million triangles) is about 150 MB as Gmsh ASCII (~70 bytes per triangle with
/// its nodes); a scene is a few kB (expressions are capped at 100,000 characters). 256 MiB leaves room
/// for both and keeps a mistaken path from filling the memory.
pub const MAX_INPUT_BYTES: u64 = 256 << 20;

/// What a file system object is, for messages ("a directory", "a FIFO", ...).
pub fn kind_of(t: std::fs::FileType) -> &'static str {
    if t.is_dir() {
        "a directory"
    } else if t.is_symlink() {
        "a symbolic link"
    } else if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_char_device() {
        "a character device"
    } else if t.is_block_device() {
        "a block device"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_file() {
        "a regular file"
    } else {
        "not a regular file"
    }
}

/// The text of the input file `path` (`what`: "scene" or "mesh", for messages): refused unless it is a
/// regular file (a symbolic link to one is followed) of at most [`MAX_INPUT_BYTES`] bytes of UTF-8.
pub fn read_text(path: &Path, what: &str) -> Result<String> {
    let err = |msg: String| Error::Io { path: path.to_path_buf(), msg };
    // O_NONBLOCK: opening a FIFO without a writer would block; regular files ignore the flag
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
        .map_err(|e| err(format!("cannot read {what}: {e}")))?;
    let meta = file.metadata().map_err(|e| err(format!("cannot read {what}: {e}")))?;
    if !meta.file_type().is_file() {
        return Err(err(format!("cannot read {what}: the path is {}, not a regular file", kind_of(meta.file_type()))));
    }
    if meta.len() > MAX_INPUT_BYTES {
        return Err(err(format!(
            "cannot read {what}: {} bytes is more than the {MAX_INPUT_BYTES} bytes (256 MiB) an input may have",
            meta.len()
        )));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // a file that grows while it is read is still cut at the limit (one byte more tells it grew beyond)
    file.take(MAX_INPUT_BYTES + 1).read_to_end(&mut bytes).map_err(|e| err(format!("cannot read {what}: {e}")))?;
    if bytes.len() as u64 > MAX_INPUT_BYTES {
        return Err(err(format!("cannot read {what}: it grew beyond {MAX_INPUT_BYTES} bytes (256 MiB) while read")));
    }
    String::from_utf8(bytes).map_err(|e| err(format!("cannot read {what}: not UTF-8 text ({e})")))
}

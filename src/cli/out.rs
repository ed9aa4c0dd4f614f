//! Terminal output that never panics. `println!` panics when standard output is a closed pipe
//! (`run -v | head -1`) or a full device (`check > /dev/full`); here the first failure is remembered,
//! later lines are dropped, and the subcommand decides what it means: `check` (whose output is its
//! result) fails with the error, `run` (whose result is its file) goes on and reports it at the end.
//! Messages to standard error are best effort: there is nowhere left to report their failure.

use std::io::Write;
use std::sync::Mutex;

static STDOUT_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Write one line to standard output, unless an earlier write failed.
pub fn line(args: std::fmt::Arguments) {
    let mut err = STDOUT_ERROR.lock().unwrap_or_else(|e| e.into_inner());
    if err.is_some() {
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")).and_then(|()| out.flush()) {
        *err = Some(e.to_string());
    }
}

/// Write one line to standard error, ignoring failure.
pub fn note_line(args: std::fmt::Arguments) {
    let mut e = std::io::stderr().lock();
    let _ = e.write_fmt(args).and_then(|()| e.write_all(b"\n"));
}

/// Why standard output could not be written, if it could not.
pub fn stdout_error() -> Option<String> {
    STDOUT_ERROR.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// `println!` that never panics (see the module doc).
macro_rules! say {
    ($($t:tt)*) => { $crate::cli::out::line(format_args!($($t)*)) };
}

/// `eprintln!` that never panics.
macro_rules! note {
    ($($t:tt)*) => { $crate::cli::out::note_line(format_args!($($t)*)) };
}

pub(crate) use {note, say};

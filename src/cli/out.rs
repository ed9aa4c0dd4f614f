//! Terminal output that never panics. `println!` panics when standard output is a closed pipe
//! (`run -v | head -1`) or a full device (`check > /dev/full`); here the first failure is remembered,
//! later lines are dropped, and the subcommand decides what it means: `check` (whose output is its
//! result) fails with the error, `run` (whose result is its file) goes on and reports it at the end.
//! Messages to standard error are best effort: there is nowhere left to report their failure.

use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

static STDOUT_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// The failed write was to a pipe whose reader has gone (`study … | head -1`): the reader took what it
/// wanted, so a report cut there is no failure.
static BROKEN_PIPE: AtomicBool = AtomicBool::new(false);

/// Standard output was closed when the process started (`>&-`). Rust's runtime then opens `/dev/null`
/// under descriptor 1 before `main`, where every write succeeds, so the closed output could not be seen
/// later: it is looked at by [`look_at_stdout`], which the C runtime calls before Rust's.
static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);

/// Record whether descriptor 1 is open; runs as a constructor of the executable (`.init_array`).
extern "C" fn look_at_stdout() {
    // SAFETY: fcntl(F_GETFD) only reads the descriptor's flags.
    if unsafe { libc::fcntl(1, libc::F_GETFD) } == -1 {
        STDOUT_CLOSED.store(true, Ordering::Relaxed);
    }
}

#[used]
#[link_section = ".init_array"]
static LOOK_AT_STDOUT: extern "C" fn() = look_at_stdout;

/// Write one line to standard output, unless an earlier write failed.
pub fn line(args: std::fmt::Arguments) {
    let mut err = STDOUT_ERROR.lock().unwrap_or_else(|e| e.into_inner());
    if err.is_some() {
        return;
    }
    if STDOUT_CLOSED.load(Ordering::Relaxed) {
        *err = Some("standard output is closed".into());
        return;
    }
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")).and_then(|()| out.flush()) {
        BROKEN_PIPE.store(e.kind() == std::io::ErrorKind::BrokenPipe, Ordering::Relaxed);
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

/// The end of a subcommand whose printed report is its result (`study`, `plan`): an error when standard
/// output could not be written (closed, a broken pipe, a full device), unless the report is also in the
/// file `kept` (`--csv`), which is then named in a warning. A reader that closed its pipe early ends the
/// subcommand quietly and successfully, as `head` expects.
pub fn report_written(kept: Option<&std::path::Path>) -> anyhow::Result<()> {
    match (stdout_error(), kept) {
        (None, _) => Ok(()),
        (Some(_), _) if BROKEN_PIPE.load(Ordering::Relaxed) => Ok(()),
        (Some(e), Some(p)) => {
            note_line(format_args!(
                "warning: standard output could not be written ({e}); the results are in {}",
                p.display()
            ));
            Ok(())
        }
        (Some(e), None) => anyhow::bail!("cannot write to standard output: {e}; the report is lost (--csv keeps it)"),
    }
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

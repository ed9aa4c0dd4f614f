//! The timeline of the set-up's phase 1 (`Discretised::assemble`): each stage of its two threads with its
//! start and end (wall seconds from the phase's start) and its thread's CPU seconds, printed to standard
//! error when `TRESCA_TIMELINE` is set, so that the critical path is known (reference/performance.md §9).
//! Unset, a stage costs one branch and nothing is printed.

use std::sync::Mutex;
use std::time::Instant;

/// The environment variable that turns the timeline on.
pub const ENV: &str = "TRESCA_TIMELINE";

/// One stage: its thread, its name, its start and end (s from the phase's start), its thread's CPU (s).
struct Row {
    thread: &'static str,
    stage: &'static str,
    span: (f64, f64),
    cpu: f64,
}

/// The stages recorded so far (`None`: off).
pub(super) struct Timeline {
    start: Instant,
    rows: Option<Mutex<Vec<Row>>>,
}

impl Timeline {
    /// A timeline starting now, on when [`ENV`] is set.
    pub(super) fn new() -> Timeline {
        Timeline { start: Instant::now(), rows: std::env::var_os(ENV).map(|_| Mutex::new(Vec::new())) }
    }

    /// `f()`, recorded as `stage` of `thread`.
    pub(super) fn stage<T>(&self, thread: &'static str, stage: &'static str, f: impl FnOnce() -> T) -> T {
        let Some(rows) = &self.rows else { return f() };
        let (from, cpu) = (self.start.elapsed().as_secs_f64(), crate::machine::thread_cpu_seconds());
        let r = f();
        let cpu = crate::machine::thread_cpu_seconds() - cpu;
        let row = Row { thread, stage, span: (from, self.start.elapsed().as_secs_f64()), cpu };
        rows.lock().unwrap_or_else(|e| e.into_inner()).push(row);
        r
    }

    /// The stages, by start, to standard error (when on).
    pub(super) fn print(&self) {
        let Some(rows) = &self.rows else { return };
        let mut rows = std::mem::take(&mut *rows.lock().unwrap_or_else(|e| e.into_inner()));
        rows.sort_by(|a, b| a.span.0.total_cmp(&b.span.0));
        eprintln!("phase 1 timeline ({ENV}): thread, stage, start s, end s, wall s, thread CPU s");
        for r in rows {
            let (a, b) = r.span;
            eprintln!("{:>9} {:>22} {a:8.3} {b:8.3} {:8.3} {:8.3}", r.thread, r.stage, b - a, r.cpu);
        }
    }
}

//! How many threads a run uses: the cores available to the process (its CPU affinity and cgroup quota,
//! `std::thread::available_parallelism`), unless `--threads N` or the environment variable
//! `TRESCA_THREADS` says otherwise. The count sizes rayon's pool (the expression evaluation of
//! [`crate::parallel`]) and the parallel kernels of the factorisation and of the large solves
//! (`solve::cholesky::factor`); results files record it (`/tresca@threads`).
//!
//! The factor, and so every result, is the same bit for bit run after run and for every count: the
//! factorisation by subtrees computes each supernode as faer's sequential kernel does
//! (`solve::cholesky::subtrees`), and faer's parallel dense kernels split their work by output blocks, each computed
//! as the sequential kernel computes it (docs/model.md, "Threads"; tested in `solve::cholesky::factor`).

use crate::error::{Error, Result};
use faer::Par;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread::{Scope, ScopedJoinHandle};

/// The environment variable that sets the thread count when `--threads` is not given.
pub const ENV: &str = "TRESCA_THREADS";

/// The count in force; 0 until [`set`] or the first [`count`].
static COUNT: AtomicUsize = AtomicUsize::new(0);

/// The cores available to this process (at least 1).
pub fn available() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// The most threads a run starts when the machine has fewer cores: every one is an OS thread of rayon's
/// pool, so a count such as 10⁶ would spend its time (or the process limit) starting threads, and more
/// threads than cores only share them (the results do not depend on the count).
pub const MAX: usize = 1024;

/// The count asked for: `flag`, else `TRESCA_THREADS`, else [`available`]. Zero, text that is not a
/// count and more than [`MAX`] (or the available cores, if more) are refused.
pub fn requested(flag: Option<usize>) -> Result<usize> {
    let n = match (flag, std::env::var(ENV)) {
        (Some(n), _) => n,
        (None, Ok(v)) => v.trim().parse().map_err(|_| bad(&v))?,
        (None, Err(_)) => available(),
    };
    if n == 0 {
        return Err(bad("0"));
    }
    let max = MAX.max(available());
    if n > max {
        return Err(Error::TooManyThreads { asked: n, max });
    }
    Ok(n)
}

fn bad(v: &str) -> Error {
    Error::Threads(v.into())
}

/// Use `n` threads from now on: the count of [`count`] and, on its first call, the size of rayon's
/// global pool (later calls change the count only; the pool keeps its size). A pool whose threads the
/// system refuses is an error ([`Error::Thread`]): rayon would panic at its first use.
pub fn set(n: usize) -> Result<()> {
    let n = n.max(1);
    COUNT.store(n, Ordering::Relaxed);
    match rayon::ThreadPoolBuilder::new().num_threads(n).build_global() {
        // only a refused thread has a source (the I/O error); a pool built before is kept
        Err(e) => match std::error::Error::source(&e) {
            Some(io) => Err(refused("rayon's pool of worker threads", io)),
            None => Ok(()),
        },
        Ok(()) => Ok(()),
    }
}

/// Start `f` on a thread of scope `s`, named `what` in the error if the system refuses it (which
/// `Scope::spawn` would turn into a panic).
pub fn scoped<'s, 'e, T: Send + 's>(
    s: &'s Scope<'s, 'e>,
    what: &'static str,
    f: impl FnOnce() -> T + Send + 's,
) -> Result<ScopedJoinHandle<'s, T>> {
    std::thread::Builder::new().spawn_scoped(s, f).map_err(|e| refused(what, &e))
}

/// The error of a thread for `what` that the system refused with `e`.
pub fn refused(what: &'static str, e: &dyn std::fmt::Display) -> Error {
    Error::Thread { what, msg: e.to_string() }
}

/// The thread count in force: the last [`set`], else `TRESCA_THREADS` or the available cores.
pub fn count() -> usize {
    match COUNT.load(Ordering::Relaxed) {
        0 => {
            let n = requested(None).unwrap_or_else(|_| available());
            COUNT.store(n, Ordering::Relaxed);
            n
        }
        n => n,
    }
}

/// faer's parallelism for the thread count in force: sequential for one thread.
pub fn par() -> Par {
    match count() {
        1 => Par::Seq,
        n => Par::rayon(n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The system shall take the thread count from `--threads`, refusing zero and more than `MAX`.
    #[test]
    fn the_flag_sets_the_count_and_zero_is_refused() {
        assert_eq!(requested(Some(3)).unwrap(), 3);
        assert!(requested(Some(0)).is_err());
        assert!(available() >= 1);
        let max = MAX.max(available());
        assert_eq!(requested(Some(max)).unwrap(), max);
        let e = requested(Some(max + 1)).unwrap_err().to_string();
        assert!(e.contains(&format!("at most {max}")), "{e}");
    }
}

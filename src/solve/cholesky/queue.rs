//! The ready tasks of the factorisation on several threads (`solve::cholesky::subtrees`): a task is ready
//! once every task it waits for is done; the threads take the ready task of highest priority
//! (`solve::cholesky::schedule`). A failed task (a pivot that is not positive) leaves the tasks waiting
//! for it never ready; the others still run, but those whose columns all come after a failure's are skipped,
//! so the failure reported is the first in column order, as faer's sequential kernel reports it.

use super::schedule::Tasks;
use faer::linalg::solvers::LltError;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::sync::{Condvar, Mutex, MutexGuard};

struct State {
    /// (priority's bits, task): priorities are non-negative, so their bits order as they do.
    ready: BinaryHeap<(u64, Reverse<usize>)>,
    below: Vec<usize>,
    running: usize,
    /// The first column whose pivot failed.
    failed: Option<usize>,
    /// A thread panicked: the others stop.
    aborted: bool,
}

pub(super) struct Queue<'a> {
    tasks: &'a Tasks,
    state: Mutex<State>,
    changed: Condvar,
}

impl<'a> Queue<'a> {
    /// The tasks that wait for none are ready.
    pub fn new(tasks: &'a Tasks) -> Queue<'a> {
        let mut ready = BinaryHeap::new();
        for (t, &b) in tasks.below.iter().enumerate() {
            if b == 0 {
                ready.push((tasks.priority[t].to_bits(), Reverse(t)));
            }
        }
        let state = State { ready, below: tasks.below.clone(), running: 0, failed: None, aborted: false };
        Queue { tasks, state: Mutex::new(state), changed: Condvar::new() }
    }

    fn lock(&self) -> MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The next task and whether it is alone (no other running or ready: none can become ready before
    /// it is done); `None` when no task is left.
    pub fn take(&self) -> Option<(usize, bool)> {
        let mut st = self.lock();
        loop {
            if st.aborted {
                return None;
            }
            if let Some((_, Reverse(t))) = st.ready.pop() {
                st.running += 1;
                let alone = st.ready.is_empty() && st.running == 1;
                return Some((t, alone));
            }
            if st.running == 0 {
                return None;
            }
            st = self.changed.wait(st).unwrap_or_else(|e| e.into_inner());
        }
    }

    /// Whether a pivot failed in a column before `column`.
    pub fn failed_before(&self, column: usize) -> bool {
        self.lock().failed.is_some_and(|f| f < column)
    }

    /// Task t is over: computed (`Ok(true)`), skipped (`Ok(false)`), or failed.
    pub fn done(&self, t: usize, r: Result<bool, LltError>) {
        let mut st = self.lock();
        st.running -= 1;
        match r {
            Ok(true) => {
                for &u in &self.tasks.next[t] {
                    st.below[u] -= 1;
                    if st.below[u] == 0 {
                        st.ready.push((self.tasks.priority[u].to_bits(), Reverse(u)));
                    }
                }
            }
            Ok(false) => {}
            Err(LltError::NonPositivePivot { index }) => st.failed = Some(st.failed.map_or(index, |f| f.min(index))),
        }
        self.changed.notify_all();
    }

    /// Stop every thread (one panicked).
    pub fn abort(&self) {
        self.lock().aborted = true;
        self.changed.notify_all();
    }

    /// The factorisation's outcome once every thread has stopped.
    pub fn result(&self) -> Result<(), LltError> {
        match self.lock().failed {
            Some(index) => Err(LltError::NonPositivePivot { index }),
            None => Ok(()),
        }
    }
}

/// Aborts the queue if its thread panics, so the other threads do not wait for it forever.
pub(super) struct Guard<'q, 'a>(pub &'q Queue<'a>);

impl Drop for Guard<'_, '_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.abort();
        }
    }
}

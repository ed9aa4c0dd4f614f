//! Order-preserving parallel map for the expensive, independent work of a step: evaluating expression
//! strings at quadrature points. Results come back in input order and every reduction stays sequential
//! in the caller, so a run is bit-identical whatever the number of threads. Short inputs stay sequential.

use rayon::prelude::*;

/// Inputs shorter than this are mapped sequentially (thread start-up would dominate).
const MIN_PARALLEL: usize = 2048;

/// `items.iter().map(f).collect()`, in parallel for long inputs, results in input order.
pub fn map<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync + Send) -> Vec<R> {
    if items.len() < MIN_PARALLEL {
        items.iter().map(f).collect()
    } else {
        items.par_iter().with_min_len(256).map(f).collect()
    }
}

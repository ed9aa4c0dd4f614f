//! Order-preserving parallel work for the expensive, independent parts of a step: evaluating
//! expressions at quadrature points. Results come back in input order (or in place) and every reduction
//! stays sequential in the caller, so a run is bit-identical whatever the number of threads. Short
//! inputs stay sequential.

use rayon::prelude::*;

/// Work below this many values (expression values at points) is done sequentially: handing work to the
/// pool and waking its workers costs tens of µs, and on small meshes (a planner's pilot levels evaluate
/// loads at every time node of 100–6,000-unknown problems) that overhead and the workers' yielding
/// cost more CPU than the evaluation (2048 → 32768: the planner's CPU on mms_stop 0.21–0.23 →
/// 0.18–0.19 s).
const MIN_PARALLEL: usize = 32768;

/// `f(i, chunk_i)` for the consecutive chunks of `chunk` entries of `out` (the last may be shorter), in
/// parallel when there are several chunks and the work, `values_per_entry` values for each entry of
/// `out`, is at least [`MIN_PARALLEL`]. Each chunk is written by one call only.
pub fn for_chunks<R: Send>(
    out: &mut [R],
    chunk: usize,
    values_per_entry: usize,
    f: impl Fn(usize, &mut [R]) + Sync + Send,
) {
    let chunk = chunk.max(1);
    if out.len() <= chunk || out.len().saturating_mul(values_per_entry) < MIN_PARALLEL {
        out.chunks_mut(chunk).enumerate().for_each(|(i, c)| f(i, c));
    } else {
        out.par_chunks_mut(chunk).enumerate().for_each(|(i, c)| f(i, c));
    }
}

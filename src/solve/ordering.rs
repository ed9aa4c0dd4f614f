//! Fill-reducing ordering P: nested dissection (METIS_NodeND) for K of [`ND_MIN_SIZE`] unknowns or
//! more, AMD (faer's) below. Why: the factorisation is flop-bound, and on a 2D mesh nested dissection
//! gives the asymptotically optimal fill, O(n log n) entries and O(n^1.5) flops, with a smaller constant
//! than AMD: on the 1.57M-unknown benchmark nnz(L) drops from 613M to 462M and the flops from 1.14e12 to
//! about 5e11, so the numeric phase halves (≈ 60 s → 29 s). But METIS itself takes ≈ 11 s there and
//! ≈ 2.5 s at 394k unknowns, where it loses overall to AMD (the set-up was 40 % slower), hence the size
//! threshold. METIS orders the graph of K with consecutive coupled unknowns (i, i+1) merged into one
//! weighted vertex: the two displacement components of an edge are numbered consecutively and are
//! coupled, so this halves the graph (and METIS's time) with nnz(L) within 1 % of ordering the full
//! graph; the merging is only a heuristic for speed, the result is a valid permutation whatever the
//! numbering. Deterministic: adjacency lists sorted, a fixed seed, and calls serialised by a lock (METIS
//! draws from the C library's global `rand`), so the same K always gets the same ordering, hence
//! bit-identical results. If METIS cannot be used (tiny or edgeless graphs, indices beyond i32, an
//! error) the ordering falls back to AMD: the ordering only affects speed.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::SparseColMat;
use std::sync::Mutex;

/// faer's approximate minimum degree ordering of K (position → unknown).
pub(super) fn amd_order(k: &SparseColMat<usize, f64>, control: amd::Control) -> Result<Vec<usize>> {
    let n = k.nrows();
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let nnz = k.symbolic().compute_nnz();
    let mut buf = MemBuffer::try_new(amd::order_maybe_unsorted_scratch::<usize>(n, nnz))
        .map_err(|_| Error::Linear("out of memory for the AMD ordering".into()))?;
    amd::order_maybe_unsorted(&mut fwd, &mut inv, k.symbolic(), control, MemStack::new(&mut buf))
        .map_err(|e| Error::Linear(format!("AMD ordering failed: {e:?}")))?;
    Ok(fwd)
}

/// Below this many unknowns K is ordered by AMD: METIS's own cost would exceed what its better ordering
/// saves in the numeric factorisation (benchmark, medians of 3: at 394k unknowns the set-up took 12.3 s
/// with METIS against 8.7 s with AMD; at 1.57M, 64 s against 73 s).
pub const ND_MIN_SIZE: usize = 1_000_000;

/// Fixed METIS seed: the ordering, hence every result, is reproducible.
const ND_SEED: i32 = 42;

/// Serialises METIS calls: its random choices come from the C library's global `rand` state, reseeded at
/// each call, so concurrent calls (parallel tests) would interleave their draws and break determinism.
static METIS_LOCK: Mutex<()> = Mutex::new(());

/// Nested-dissection ordering (forward, inverse) of the graph of K by METIS_NodeND, or `None` when
/// METIS cannot be used: the caller then falls back to AMD.
pub(super) fn nested_dissection(k: &SparseColMat<usize, f64>) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = k.nrows();
    let (col_ptr, row_idx) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
    let coupled = |i: usize, j: usize| {
        row_idx[col_ptr[i]..col_ptr[i + 1]].contains(&j) || row_idx[col_ptr[j]..col_ptr[j + 1]].contains(&i)
    };
    // Vertices of METIS's graph: groups first[g]..first[g + 1] of one unknown, or of two consecutive
    // coupled ones (both components of an edge's displacement).
    let mut group = vec![0usize; n];
    let mut first = Vec::with_capacity(n / 2 + 2);
    let mut i = 0;
    while i < n {
        group[i] = first.len();
        first.push(i);
        if i + 1 < n && coupled(i, i + 1) {
            group[i + 1] = group[i];
            i += 2;
        } else {
            i += 1;
        }
    }
    let ng = first.len();
    first.push(n);
    // Symmetric adjacency of the groups, without self loops, from whichever triangle(s) K stores.
    let mut deg = vec![0usize; ng];
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if group[i] != group[j] {
                deg[group[i]] += 1;
                deg[group[j]] += 1;
            }
        }
    }
    let mut start = vec![0usize; ng + 1];
    for g in 0..ng {
        start[g + 1] = start[g] + deg[g];
    }
    drop(deg);
    let mut adj = vec![0u32; start[ng]];
    let mut fill = start[..ng].to_vec();
    for j in 0..n {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            let (gi, gj) = (group[i], group[j]);
            if gi != gj {
                adj[fill[gi]] = gj as u32;
                fill[gi] += 1;
                adj[fill[gj]] = gi as u32;
                fill[gj] += 1;
            }
        }
    }
    drop(fill);
    let mut xadj: Vec<i32> = Vec::with_capacity(ng + 1);
    let mut adjncy: Vec<i32> = Vec::new();
    xadj.push(0);
    for g in 0..ng {
        let row = &mut adj[start[g]..start[g + 1]];
        row.sort_unstable();
        let mut last = u32::MAX;
        for &h in row.iter() {
            if h != last {
                adjncy.push(i32::try_from(h).ok()?);
                last = h;
            }
        }
        xadj.push(i32::try_from(adjncy.len()).ok()?);
    }
    drop(adj);
    if adjncy.is_empty() {
        return None;
    }
    let mut vwgt: Vec<i32> = (0..ng).map(|g| (first[g + 1] - first[g]) as i32).collect();
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut nvtxs = i32::try_from(ng).ok()?;
    let (mut perm, mut iperm) = (vec![0i32; ng], vec![0i32; ng]);
    let status = {
        let _guard = METIS_LOCK.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: `options` has METIS_NOPTIONS entries; xadj has ng + 1 entries, adjncy xadj[ng] (all
        // in 0..ng, no self loops, symmetric), vwgt, perm and iperm ng each. METIS reads the graph and
        // options and writes only perm and iperm.
        unsafe {
            metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
            options[metis_sys::moptions_et_METIS_OPTION_SEED as usize] = ND_SEED;
            options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
            metis_sys::METIS_NodeND(
                &mut nvtxs,
                xadj.as_mut_ptr(),
                adjncy.as_mut_ptr(),
                vwgt.as_mut_ptr(),
                options.as_mut_ptr(),
                perm.as_mut_ptr(),
                iperm.as_mut_ptr(),
            )
        }
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    // METIS: perm[new] = old. Expand each group into its unknowns, in order.
    let mut fwd = Vec::with_capacity(n);
    for &g in &perm {
        let g = usize::try_from(g).ok().filter(|&g| g < ng)?;
        fwd.extend(first[g]..first[g + 1]);
    }
    let mut inv = vec![usize::MAX; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    if fwd.len() != n || inv.contains(&usize::MAX) {
        return None;
    }
    Some((fwd, inv))
}

//! The numeric supernodal factorisation on several threads, by subtrees of the supernodal elimination
//! tree. faer's kernel (`factorize_supernodal_numeric_llt`) walks the supernodes in order and splits only
//! each supernode's dense work between threads, which leaves the many small supernodes of a 2D problem on
//! one thread. Here the tasks of `solve::cholesky::schedule` (whole subtrees, and the supernodes above
//! them in parts: their updates from each task below as soon as it is done, then their dense work) run
//! on the threads as they become ready (`solve::cholesky::queue`): a supernode reads only its
//! descendants' columns of L and writes only its own. A task that runs alone (no other can start before
//! it ends) splits its dense work between the threads. Every supernode is computed as faer's kernel computes it:
//! the same updates in the same order, with faer's own kernels (its update kernel, `private_gemm_x86`,
//! called with the arguments faer gives it), so the factor is faer's sequential one bit for bit whatever
//! the thread count (test: `solve::cholesky::factor::tests::two_threads_factorise_bit_identically_run_after_run`).

use super::queue::{Guard, Queue};
use super::schedule::{self, Job, Tasks, Tree};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::{cholesky_in_place, cholesky_in_place_scratch};
use faer::linalg::solvers::LltError;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::supernodal::SymbolicSupernodalCholesky;
use faer::sparse::SparseColMatRef;
use faer::{MatMut, MatRef, Par};

/// Factors with fewer entries are computed sequentially (`Factor::numeric_beside`): their factorisation
/// takes about a millisecond, so threads would save a fraction of one while starting them (tens of µs a
/// round) would be paid on every small mesh, as a planner's pilot levels make them by the hundred.
pub(crate) const MIN_ENTRIES: usize = 1 << 16;

type Numeric = std::result::Result<(), LltError>;

/// The threads of the factorisation by subtrees with faer's parallelism `par` for a matrix of n rows:
/// `None` where it is not used (one thread; a machine without faer's update kernel, x86-64 with AVX2 and
/// FMA; rows beyond `u32`), and faer's own numeric factorisation computes the factor.
pub(super) fn threads_of(par: Par, n: usize) -> Option<usize> {
    match par {
        Par::Rayon(t) if t.get() > 1 && instr_set().is_some() && schedule::fits_u32(n) => Some(t.get()),
        _ => None,
    }
}

#[cfg(target_arch = "x86_64")]
fn instr_set() -> Option<private_gemm_x86::InstrSet> {
    use private_gemm_x86::InstrSet;
    if std::arch::is_x86_feature_detected!("avx512f") {
        Some(InstrSet::Avx512)
    } else if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        Some(InstrSet::Avx256)
    } else {
        None
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn instr_set() -> Option<()> {
    None
}

/// L's values, written by several threads, each supernode's block by one only.
struct Values(*mut f64, usize);
// SAFETY: blocks are handed out by `block_mut` to one thread each, and read by `block` only once written
// (a supernode reads its descendants', finished before it starts: same thread, or joined threads).
unsafe impl Sync for Values {}

impl Values {
    /// # Safety
    /// No other thread writes `a..b` while the slice lives.
    unsafe fn block(&self, a: usize, b: usize) -> &[f64] {
        assert!(a <= b && b <= self.1);
        std::slice::from_raw_parts(self.0.add(a), b - a)
    }

    /// # Safety
    /// No other thread reads or writes `a..b` while the slice lives.
    #[allow(clippy::mut_from_ref)]
    unsafe fn block_mut(&self, a: usize, b: usize) -> &mut [f64] {
        assert!(a <= b && b <= self.1);
        std::slice::from_raw_parts_mut(self.0.add(a), b - a)
    }
}

/// What every supernode's computation reads.
struct Ctx<'a> {
    symbolic: &'a SymbolicSupernodalCholesky<usize>,
    a: SparseColMatRef<'a, usize, f64>,
    values: Values,
    tree: Tree,
}

/// Bytes [`factorize`] allocates with `threads` threads beside L, the permuted matrix and the row maps
/// ([`maps_len`]), where the supernodal tree has `updates` updates ([`schedule::count_updates`]): the tree
/// (three words a supernode, a `u32` and an `f64` an update), the pointers to the updates while it is
/// built (a word a supernode), then the tasks (at most five words a supernode) and each thread's dense
/// scratch (and the indices of one update, a few words).
pub(crate) fn scratch_bytes(symbolic: &SymbolicSupernodalCholesky<usize>, threads: usize, updates: usize) -> u64 {
    let word = std::mem::size_of::<usize>() as u64;
    let (ns, updates) = (symbolic.n_supernodes() as u64, updates as u64);
    let tree = word * (3 * ns + 2) + 12 * updates;
    let widest = (0..symbolic.n_supernodes()).map(|s| width(symbolic, s)).max().unwrap_or(0);
    let dense = cholesky_in_place_scratch::<f64>(widest, Par::rayon(threads), Default::default());
    let running = 5 * word * ns + threads as u64 * dense.unaligned_bytes_required() as u64;
    tree + (word * (ns + 1)).max(running)
}

/// The `u32`s of the row maps that [`factorize`] is given: one a row for each thread (the first also holds
/// the supernode of each column while the tree is built). `numeric_scratch` gives them the space of the
/// permutation's scratch, free once K is permuted.
pub(crate) fn maps_len(n: usize, threads: usize) -> usize {
    n * threads
}

/// The number of updates of the supernodal tree of `symbolic` (see [`scratch_bytes`]).
pub(crate) fn count_updates(symbolic: &SymbolicSupernodalCholesky<usize>) -> usize {
    schedule::count_updates(symbolic.supernode_begin(), symbolic.supernode_end(), symbolic.nrows(), |s| {
        pattern(symbolic, s)
    })
}

/// L's values of the lower triangle `a` (permuted) with `threads` threads (≥ 2), as faer's
/// `factorize_supernodal_numeric_llt` with default parameters computes them. `values` must be zeros.
/// The tasks of [`Tasks`] run on the threads as they become ready (`solve::cholesky::schedule`), each
/// with faer's sequential dense kernels, or its parallel ones when it is the only task that can run.
pub(super) fn factorize(
    values: &mut [f64],
    a: SparseColMatRef<'_, usize, f64>,
    symbolic: &SymbolicSupernodalCholesky<usize>,
    (threads, maps): (usize, &mut [u32]),
) -> Numeric {
    let n = symbolic.nrows();
    assert!(maps.len() >= maps_len(n, threads));
    let tree =
        Tree::new(symbolic.supernode_begin(), symbolic.supernode_end(), &mut maps[..n], |s| pattern(symbolic, s));
    maps.fill(u32::MAX);
    let tasks = Tasks::new(&tree, threads);
    if std::env::var_os(schedule::ENV).is_some() {
        let [total, critical, makespan, alone] = tasks.figures(threads);
        eprintln!(
            "schedule: {} tasks, work {total:.4e}, critical path {critical:.4e} ({:.3}), makespan on {threads} \
             threads {makespan:.4e} (speed-up {:.3}), of which alone {alone:.4e} ({:.3})",
            tasks.work.len(),
            critical / total,
            total / makespan,
            alone / total
        );
    }
    let ctx = Ctx { symbolic, a, values: Values(values.as_mut_ptr(), values.len()), tree };
    let queue = Queue::new(&tasks);
    std::thread::scope(|sc| {
        let (ctx, tasks, queue) = (&ctx, &tasks, &queue);
        let mut maps = maps.chunks_exact_mut(n).take(threads);
        while let Some(g2l) = maps.next() {
            let start = std::thread::Builder::new().spawn_scoped(sc, move || worker(ctx, tasks, queue, (threads, g2l)));
            // a thread the system refuses: this one works with the next map (any number of workers ends the
            // queue; with none left, an earlier thread was started: `threads` ≥ 2)
            if start.is_err() {
                if let Some(g2l) = maps.next() {
                    worker(ctx, tasks, queue, (threads, g2l));
                }
                break;
            }
        }
    });
    queue.result()
}

/// One thread's share: the ready tasks it takes, until none is left.
fn worker(ctx: &Ctx, tasks: &Tasks, queue: &Queue, (threads, g2l): (usize, &mut [u32])) {
    let _guard = Guard(queue);
    let widest = (0..ctx.symbolic.n_supernodes()).map(|s| width(ctx.symbolic, s)).max().unwrap_or(0);
    let mut scratch = Scratch {
        g2l,
        idx: (Vec::new(), Vec::new()),
        mem: MemBuffer::new(cholesky_in_place_scratch::<f64>(widest, Par::rayon(threads), Default::default())),
    };
    while let Some((t, alone)) = queue.take() {
        let par = if alone { Par::rayon(threads) } else { Par::Seq };
        let first = ctx.symbolic.supernode_begin()[tasks.first_supernode(t)];
        let r = if queue.failed_before(first) { Ok(false) } else { job(ctx, &tasks.jobs[t], par, &mut scratch) };
        queue.done(t, r);
    }
}

/// A thread's scratch: the row map (global row → row in the supernode's block, `u32::MAX` elsewhere), the
/// update's indices, the dense factor's memory.
struct Scratch<'m> {
    g2l: &'m mut [u32],
    idx: (Vec<usize>, Vec<usize>),
    mem: MemBuffer,
}

/// Compute `job` with the parallelism `par` in its dense work: `Ok(true)` once done.
fn job(ctx: &Ctx, job: &Job, par: Par, sc: &mut Scratch<'_>) -> Result<bool, LltError> {
    match *job {
        Job::Whole(ref list) => {
            for &s in list {
                let (from, to) = (ctx.tree.update_ptr[s], ctx.tree.update_ptr[s + 1]);
                updates(ctx, s, (from, to), true, par, sc);
                dense(ctx, s, par, MemStack::new(&mut sc.mem))?;
            }
        }
        Job::Update { s, from, to, first } => updates(ctx, s, (from, to), first, par, sc),
        Job::Dense(s) => dense(ctx, s, par, MemStack::new(&mut sc.mem))?,
    }
    Ok(true)
}

fn pattern(symbolic: &SymbolicSupernodalCholesky<usize>, s: usize) -> &[usize] {
    &symbolic.row_idx()[symbolic.col_ptr_for_row_idx()[s]..][..symbolic.nnz_per_super()[s]]
}

fn width(symbolic: &SymbolicSupernodalCholesky<usize>, s: usize) -> usize {
    symbolic.supernode_end()[s] - symbolic.supernode_begin()[s]
}

/// Supernode s's block of L: its rows, its columns.
fn block<'a>(ctx: &'a Ctx, s: usize) -> MatMut<'a, f64> {
    let (sym, cpv) = (ctx.symbolic, ctx.symbolic.col_ptr_for_val());
    // SAFETY: supernode s is computed by one task at a time (its tasks wait for each other)
    let block = unsafe { ctx.values.block_mut(cpv[s], cpv[s + 1]) };
    MatMut::from_column_major_slice_mut(block, pattern(sym, s).len() + width(sym, s), width(sym, s))
}

/// Of supernode s, as faer's kernel computes it: K's columns (if `first`), then the updates of the
/// supernodes `updaters[from..to]`, in order.
fn updates(ctx: &Ctx, s: usize, (from, to): (usize, usize), first: bool, par: Par, sc: &mut Scratch<'_>) {
    let sym = ctx.symbolic;
    let cpv = sym.col_ptr_for_val();
    let (s_start, s_end) = (sym.supernode_begin()[s], sym.supernode_end()[s]);
    let s_pattern = pattern(sym, s);
    let s_ncols = s_end - s_start;
    let (g2l, (row_idx, col_idx)) = (&mut sc.g2l, &mut sc.idx);
    for (i, &row) in s_pattern.iter().enumerate() {
        g2l[row] = (i + s_ncols) as u32;
    }
    if first {
        // SAFETY: supernode s is computed by one task at a time, and this is its first
        write_first(unsafe { ctx.values.block_mut(cpv[s], cpv[s + 1]) });
    }
    let mut ls = block(ctx, s);
    if first {
        for j in s_start..s_end {
            for (i, &v) in ctx.a.row_idx_of_col(j).zip(ctx.a.val_of_col(j)) {
                if i >= j {
                    ls[(if i >= s_end { g2l[i] as usize } else { i - s_start }, j - s_start)] += v;
                }
            }
        }
    }
    for &d in &ctx.tree.updaters[from..to] {
        let d = d as usize;
        let d_pattern = pattern(sym, d);
        let d_ncols = width(sym, d);
        // SAFETY: d is below s in the tree: done before this task started, and no longer written
        let ld = unsafe { ctx.values.block(cpv[d], cpv[d + 1]) };
        let ld = MatRef::from_column_major_slice(ld, d_pattern.len() + d_ncols, d_ncols);
        let lo = d_pattern.partition_point(|&r| r < s_start);
        let mid = d_pattern[lo..].partition_point(|&r| r < s_end);
        let ld_mid_bot = ld.subrows(d_ncols + lo, d_pattern.len() - lo);
        row_idx.clear();
        row_idx.extend(
            d_pattern[lo..].iter().enumerate().map(|(i, &r)| if i < mid { r - s_start } else { g2l[r] as usize }),
        );
        col_idx.clear();
        col_idx.extend(d_pattern[lo..lo + mid].iter().map(|&r| r - s_start));
        update(ls.rb_mut(), row_idx, col_idx, ld_mid_bot, ld_mid_bot.subrows(0, mid).transpose(), par);
    }
    s_pattern.iter().for_each(|&row| g2l[row] = u32::MAX);
}

/// Touch each page of a block of zeros (one not yet computed) by a write first: its entries are then read
/// and written (`+=`), and a page read first is mapped to the kernel's shared zero page, whose copy on the
/// first write flushes the TLB of the other threads' cores, an interrupt to each (on the project's 2-core
/// VMs a tenth of the factorisation's CPU at 1.57 M unknowns; reference/performance.md §9). The pages
/// the mapping thread (`solve::cholesky::pages`) has populated are written in place, unchanged.
fn write_first(zeros: &mut [f64]) {
    const PER_PAGE: usize = 4096 / std::mem::size_of::<f64>();
    let Some(head) = zeros.first_mut() else { return };
    // SAFETY: a volatile write of the value the entry holds (0.0), so that it is not elided
    unsafe { std::ptr::write_volatile(head, 0.0) };
    let skip = (PER_PAGE - (zeros.as_ptr() as usize / 8) % PER_PAGE) % PER_PAGE;
    for v in zeros.iter_mut().skip(skip).step_by(PER_PAGE) {
        // SAFETY: as above, on the first entry of each following page
        unsafe { std::ptr::write_volatile(v, 0.0) };
    }
}

/// Of supernode s, once its updates are done: the dense Cholesky factor of its diagonal block and the
/// solve of the block below it.
fn dense(ctx: &Ctx, s: usize, par: Par, stack: &mut MemStack) -> Numeric {
    let s_start = ctx.symbolic.supernode_begin()[s];
    let mut ls = block(ctx, s);
    let (mut top, mut bot) = ls.rb_mut().split_at_row_mut(width(ctx.symbolic, s));
    cholesky_in_place(top.rb_mut(), Default::default(), par, stack, Default::default())
        .map_err(|LltError::NonPositivePivot { index }| LltError::NonPositivePivot { index: index + s_start })?;
    solve_lower_triangular_in_place(top.rb().conjugate(), bot.rb_mut().transpose_mut(), par);
    Ok(())
}

/// C[row_idx, col_idx] −= A Bᵀ on the lower triangle of C (B given transposed), as faer's supernodal
/// kernel calls its update kernel (`spicy_matmul`): sequential below 32³ multiply-adds.
#[cfg(target_arch = "x86_64")]
fn update(c: MatMut<'_, f64>, row_idx: &[usize], col_idx: &[usize], a: MatRef<'_, f64>, b: MatRef<'_, f64>, par: Par) {
    use private_gemm_x86::{gemm, Accum, DType, DstKind, IType};
    let (nrows, ncols, depth) = (a.nrows(), b.ncols(), a.ncols());
    assert!(row_idx.len() == nrows && col_idx.len() == ncols && b.nrows() == depth);
    assert!(row_idx.iter().all(|&i| i < c.nrows()) && col_idx.iter().all(|&j| j < c.ncols()));
    if nrows == 0 || ncols == 0 {
        return;
    }
    let Some(instr) = instr_set() else {
        unreachable!("subtrees::factorize is used only where threads_of gives threads")
    };
    let par = if (nrows * ncols).saturating_mul(depth) > 32 * 32 * 32 { par } else { Par::Seq };
    let alpha = -1.0f64;
    // SAFETY: the shapes, strides and indices are those checked above, as faer's spicy_matmul passes them
    unsafe {
        gemm(
            DType::F64,
            IType::U64,
            instr,
            nrows,
            ncols,
            depth,
            c.as_ptr_mut() as _,
            c.row_stride(),
            c.col_stride(),
            row_idx.as_ptr() as _,
            col_idx.as_ptr() as _,
            DstKind::Lower,
            Accum::Add,
            a.as_ptr() as _,
            a.row_stride(),
            a.col_stride(),
            false,
            std::ptr::null(),
            0,
            b.as_ptr() as _,
            b.row_stride(),
            b.col_stride(),
            true,
            &raw const alpha as _,
            par.degree(),
        );
    }
}

#[cfg(not(target_arch = "x86_64"))]
fn update(_: MatMut<'_, f64>, _: &[usize], _: &[usize], _: MatRef<'_, f64>, _: MatRef<'_, f64>, _: Par) {
    unreachable!("subtrees::factorize is used only where threads_of gives threads")
}

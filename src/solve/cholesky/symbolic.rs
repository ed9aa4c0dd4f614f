//! The symbolic half of the Cholesky factorisation ([`super::factor`]): the fill-reducing ordering
//! with the unknowns ordered last moved to its end, and the structure of L. It needs only K's pattern,
//! so `stepping` computes it while K's values are assembled.
//!
//! L's elimination tree and column counts come from [`super::etree`] (O(|K|)), and faer's supernodal
//! analysis (`factorize_supernodal_symbolic_cholesky`) makes the supernodes from them: the same
//! structure as faer's complete analysis, whose row-subtree walk costs O(|L|).

use super::dissect::coordinate_dissection;
use super::etree::{
    column_counts, elimination_tree, permuted_upper, postorder, symmetric, Adjacency, Cols, Pattern, NONE,
};
use super::ordering::{amd_order, nested_dissection, Graph};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::simplicial::EliminationTreeRef;
use faer::sparse::linalg::cholesky::supernodal::{
    factorize_supernodal_numeric_llt_scratch, factorize_supernodal_symbolic_cholesky,
    factorize_supernodal_symbolic_cholesky_scratch, SymbolicSupernodalCholesky,
};
use faer::sparse::linalg::cholesky::CholeskySymbolicParams;
use faer::sparse::SymbolicSparseColMatRef;
use faer::Par;
use std::sync::OnceLock;

/// The symbolic factorisation of a sparsity pattern: the ordering (fill-reducing, with the unknowns
/// `last` moved to its end) and the structure of L. It needs only K's pattern, so it is computed
/// while K's values are assembled ([`Factor::numeric`] then fills it).
pub struct Symbolic {
    pub(super) symbolic: SymbolicSupernodalCholesky<usize>,
    /// The ordering: position → unknown, and its inverse.
    pub(super) fwd: Vec<usize>,
    pub(super) inv: Vec<usize>,
    pub(super) last: Vec<usize>,
    /// Entries of the pattern's lower triangle (the matrix factorised must have the same pattern).
    pub(super) pattern_nnz: usize,
    /// How the fill-reducing ordering was made, as a run reports it ("given" unless named).
    pub(super) ordering: &'static str,
    /// The updates between L's supernodes, counted once asked for (the factorisation by subtrees' scratch).
    updates: OnceLock<usize>,
}

impl Symbolic {
    /// The symbolic factorisation of the symmetric `pattern` (its lower triangle read: the lower
    /// triangle alone or both triangles stored, and the matrix factorised the same) with the
    /// fill-reducing ordering `base` (position → unknown, a permutation; from [`fill_order`]) and the
    /// distinct unknowns `last` moved to its end, in the given order.
    pub fn new(pattern: SymbolicSparseColMatRef<'_, usize>, last: &[usize], base: Vec<usize>) -> Result<Symbolic> {
        let (fwd, inv) = ordering_with_last(pattern.nrows(), last, base)?;
        let sym = symmetric(pattern);
        let (symbolic, pattern_nnz) = supernodal_structure(&sym.cols(), (&fwd, &inv))?;
        Ok(Symbolic::of_parts(symbolic, (fwd, inv), last, pattern_nnz))
    }

    /// As [`Symbolic::new`], from the graph of the unknowns' groups (`fem::assemble::EdgePattern::unknown_graph`)
    /// read as the pattern of its unknowns, every block of two coupled groups whole: K's pattern, which
    /// need not be made first (the same structure as [`Symbolic::from_symmetric`] of K's pattern).
    pub fn from_graph(graph: &Graph, last: &[usize], base: Vec<usize>) -> Result<Symbolic> {
        let (fwd, inv) = ordering_with_last(graph.unknowns(), last, base)?;
        // on the groups' graph where the ordering keeps each group together (the same structure, a
        // quarter of the work: super::grouped), else on the expanded pattern
        let (symbolic, pattern_nnz) = match super::grouped::structure(graph, (&fwd, &inv)) {
            Some(s) => supernodal_of(s.upper, &s.parent, &s.counts)?,
            None => supernodal_structure(&graph.expanded(), (&fwd, &inv))?,
        };
        Ok(Symbolic::of_parts(symbolic, (fwd, inv), last, pattern_nnz))
    }

    /// As [`Symbolic::new`], from a symmetric pattern with both triangles stored (compact: without
    /// separate column lengths), such as K's full pattern: no copy of it is made.
    pub fn from_symmetric(
        sym: SymbolicSparseColMatRef<'_, usize>,
        last: &[usize],
        base: Vec<usize>,
    ) -> Result<Symbolic> {
        let cols = Cols::of(sym).ok_or_else(|| Error::Linear("internal: the pattern is not compact".into()))?;
        let (fwd, inv) = ordering_with_last(sym.nrows(), last, base)?;
        let (symbolic, pattern_nnz) = supernodal_structure(&cols, (&fwd, &inv))?;
        Ok(Symbolic::of_parts(symbolic, (fwd, inv), last, pattern_nnz))
    }

    fn of_parts(
        symbolic: SymbolicSupernodalCholesky<usize>,
        (fwd, inv): (Vec<usize>, Vec<usize>),
        last: &[usize],
        pattern_nnz: usize,
    ) -> Symbolic {
        let (last, updates) = (last.to_vec(), OnceLock::new());
        Symbolic { symbolic, fwd, inv, last, pattern_nnz, ordering: "given", updates }
    }

    /// Entries of the lower triangle of the pattern it was made from (of the matrix factorised).
    pub fn pattern_nnz(&self) -> usize {
        self.pattern_nnz
    }

    /// Entries of L (supernodal blocks included).
    pub fn len_val(&self) -> usize {
        self.symbolic.len_val()
    }

    /// Floating-point operations of the numeric factorisation and entries of L, as
    /// [`super::factor::Factor::flops_and_entries`] counts them (before the numeric factorisation).
    pub fn flops_and_entries(&self) -> (f64, f64) {
        flops_and_entries(&self.symbolic)
    }

    /// The supernodes of L (relaxed).
    pub fn n_supernodes(&self) -> usize {
        self.symbolic.n_supernodes()
    }

    /// Whether `other` is the same factorisation: the same ordering, pattern entries and structure of L
    /// (its supernodes and their row indices, in the same order).
    pub fn same_structure(&self, other: &Symbolic) -> bool {
        let (a, b) = (&self.symbolic, &other.symbolic);
        (&self.fwd, &self.inv, &self.last, self.pattern_nnz) == (&other.fwd, &other.inv, &other.last, other.pattern_nnz)
            && a.supernode_begin() == b.supernode_begin()
            && a.supernode_end() == b.supernode_end()
            && a.col_ptr_for_row_idx() == b.col_ptr_for_row_idx()
            && a.row_idx() == b.row_idx()
    }

    /// The same, its ordering named `ordering` (reported by runs: [`super::factor::Factor::ordering`]).
    pub fn ordered_by(self, ordering: &'static str) -> Symbolic {
        Symbolic { ordering, ..self }
    }

    /// The parallelism of the numeric factorisation with the thread count in force: one thread for a
    /// small factor, whose work is over before threads would have started (`subtrees::MIN_ENTRIES`).
    pub(super) fn par_in_force(&self) -> Par {
        if self.len_val() < super::subtrees::MIN_ENTRIES {
            Par::Seq
        } else {
            crate::threads::par()
        }
    }

    /// Bytes the numeric factorisation allocates with `par`: L's values and its scratch (with several
    /// threads, that of the factorisation by subtrees too: `None`).
    pub(super) fn need(&self, par: Par) -> (u64, Option<u64>) {
        let symbolic = &self.symbolic;
        let scratch = numeric_scratch(symbolic, self.pattern_nnz, par).unaligned_bytes_required() as u64;
        let subtrees = super::subtrees::threads_of(par, symbolic.nrows()).map(|t| {
            let updates = *self.updates.get_or_init(|| super::subtrees::count_updates(symbolic));
            super::subtrees::scratch_bytes(symbolic, t, updates)
        });
        let bytes = (symbolic.len_val() as u64).saturating_mul(8).saturating_add(scratch);
        (bytes.saturating_add(subtrees.unwrap_or(0)), subtrees)
    }

    /// Whether the numeric factorisation fits in the memory this machine has now
    /// (`machine::available_memory`; `true` where the machine does not say), on the threads in force or
    /// else on one ([`Symbolic::par_that_fits`]), with `beside` bytes the caller holds all along and `after`
    /// bytes it allocates once the factor is made (when the factorisation's scratch is freed).
    pub fn fits(&self, beside: u64, after: u64) -> bool {
        self.par_that_fits((beside, after), self.par_in_force(), crate::machine::available_memory()).is_ok()
    }

    /// The parallelism the numeric factorisation can afford in `have` bytes (the memory available; `None`:
    /// unknown): `par` when its values and scratch fit, with `beside` bytes held all along and `after` bytes
    /// allocated once the scratch is freed (so the larger of scratch and `after` counts), else one thread when
    /// that fits (the factor is the same bit for bit for every thread count: docs/model.md "Threads"; one
    /// thread needs no scratch of the factorisation by subtrees), else the refusal, naming the bytes
    /// needed on one thread and those available. L's pages are mapped lazily, so an allocation that does
    /// not fit would succeed and the process be killed later. The sizes are exact once the symbolic
    /// factorisation is done, where the pre-run estimate (`scene::budget`) is a fit. With
    /// `TRESCA_SCHEDULE` set (`solve::cholesky::schedule`) the figures go to standard error.
    pub(super) fn par_that_fits(&self, (beside, after): (u64, u64), par: Par, have: Option<u64>) -> Result<Par> {
        let (n, len_val) = (self.symbolic.nrows(), self.symbolic.len_val());
        let factor = (len_val as u64).saturating_mul(8);
        // the values, what is held beside, and the larger of the scratch and what comes after
        let with = |need: u64| factor.saturating_add(beside).saturating_add(need.saturating_sub(factor).max(after));
        let (need, subtrees) = self.need(par);
        let need = with(need);
        let chosen = match refuse_beyond(need, have, n, len_val) {
            Ok(()) => Ok(par),
            Err(_) => refuse_beyond(with(self.need(Par::Seq).0), have, n, len_val).map(|()| Par::Seq),
        };
        if std::env::var_os(super::schedule::ENV).is_some() {
            let threads = chosen.as_ref().map_or("refused".into(), |p| format!("{} thread(s)", p.degree()));
            let sym = &self.symbolic;
            eprintln!(
                "memory: {n} rows, {} supernodes, {} pattern rows, {:?} updates; factor {} B, need {need} B on {} \
                 thread(s) (of which the schedule's {} B) with {beside} B beside and {after} B after, available {have:?} B: \
                 {threads}",
                sym.n_supernodes(),
                sym.row_idx().len(),
                self.updates.get(),
                8 * len_val as u64,
                par.degree(),
                subtrees.unwrap_or(0)
            );
        }
        chosen
    }
}

/// The ordering `base` (position → unknown) of n unknowns with the distinct unknowns `last` moved
/// to its end, in the given order: (fwd, inv), position → unknown and unknown → position.
fn ordering_with_last(n: usize, last: &[usize], base: Vec<usize>) -> Result<(Vec<usize>, Vec<usize>)> {
    if base.len() != n || !is_permutation(&base) {
        return Err(Error::Linear("internal: the fill-reducing ordering is not a permutation of the unknowns".into()));
    }
    let mut is_last = vec![false; n];
    for &i in last {
        if i >= n || std::mem::replace(&mut is_last[i], true) {
            return Err(Error::Linear(format!("unknown {i} cannot be ordered last (out of range or repeated)")));
        }
    }
    let fwd: Vec<usize> = base.into_iter().filter(|&i| !is_last[i]).chain(last.iter().copied()).collect();
    let mut inv = vec![0usize; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    Ok((fwd, inv))
}

/// Entries of a pattern's lower triangle, diagonal included (what the numeric factorisation reads).
pub(super) fn lower_nnz(pattern: SymbolicSparseColMatRef<'_, usize>) -> usize {
    (0..pattern.ncols()).map(|j| pattern.row_idx_of_col_raw(j).iter().filter(|&&i| i >= j).count()).sum()
}

/// L's supernodal structure for the ordering (fwd, inv) of the symmetric pattern `sym` (both
/// triangles; the order of a column's rows does not matter): the elimination tree and column counts of [`super::etree`], then faer's supernodal
/// analysis (supernodes, relaxed as faer's default, and their row patterns); with the entries of the
/// pattern's lower triangle (as many as P A Pᵀ's upper one has).
fn supernodal_structure(
    sym: &impl Adjacency,
    (fwd, inv): (&[usize], &[usize]),
) -> Result<(SymbolicSupernodalCholesky<usize>, usize)> {
    let upper = permuted_upper(sym, fwd, inv);
    let parent = elimination_tree(&upper);
    let counts = column_counts(sym, (fwd, inv), &parent, &postorder(&parent), |_| 1);
    supernodal_of(upper, &parent, &counts)
}

/// faer's supernodal analysis of the permuted upper triangle `upper` with its elimination tree and
/// column counts; with the entries of the pattern's lower triangle.
fn supernodal_of(
    upper: Pattern,
    parent: &[usize],
    counts: &[usize],
) -> Result<(SymbolicSupernodalCholesky<usize>, usize)> {
    let n = parent.len();
    // what faer's analysis relies on (it indexes by them): parents after their children, counts of
    // at least the diagonal and at most the rows below it
    let tree_ok = parent.iter().enumerate().all(|(j, &p)| p == NONE || (p > j && p < n));
    if !tree_ok || counts.iter().enumerate().any(|(j, &c)| c == 0 || c > n - j) {
        return Err(Error::Linear("internal: malformed elimination tree or column counts".into()));
    }
    let etree: Vec<isize> = parent.iter().map(|&p| if p == NONE { -1 } else { p as isize }).collect();
    let pattern_nnz = upper.idx.len();
    let upper = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &upper.ptr, None, &upper.idx);
    let mut mem = MemBuffer::try_new(factorize_supernodal_symbolic_cholesky_scratch::<usize>(n))
        .map_err(|_| Error::Linear("out of memory for the symbolic Cholesky factorisation".into()))?;
    // SAFETY: faer asks for the tree its `prefactorize_symbolic_cholesky` makes from the same matrix;
    // the elimination tree of a pattern is unique, and `etree::tests` checks that both agree.
    let etree = unsafe { EliminationTreeRef::<usize>::from_inner(&etree) };
    let params = CholeskySymbolicParams::default().supernodal_params;
    factorize_supernodal_symbolic_cholesky(upper, etree, counts, MemStack::new(&mut mem), params)
        .map(|s| (s, pattern_nnz))
        .map_err(|e| Error::Linear(format!("symbolic Cholesky failed: {e:?}")))
}

/// The scratch of the numeric factorisation: K permuted (values, column pointers, row indices), as
/// faer's `SymbolicCholesky::factorize_numeric_llt` allocates it, then the supernodal kernel's (or, on
/// several threads, the row maps of the factorisation by subtrees).
pub(super) fn numeric_scratch(
    symbolic: &SymbolicSupernodalCholesky<usize>,
    pattern_nnz: usize,
    par: Par,
) -> faer::dyn_stack::StackReq {
    use faer::dyn_stack::StackReq;
    let n = symbolic.nrows();
    let permuted = StackReq::all_of(&[
        StackReq::new::<f64>(pattern_nnz),
        StackReq::new::<usize>(n + 1),
        StackReq::new::<usize>(pattern_nnz),
    ]);
    // the permutation's scratch (n words), then the kernel's, or the row maps of the factorisation by
    // subtrees (which allocates the rest of its scratch: `subtrees::scratch_bytes`)
    let kernel = match super::subtrees::threads_of(par, n) {
        Some(t) => StackReq::new::<u32>(super::subtrees::maps_len(n, t)),
        None => factorize_supernodal_numeric_llt_scratch::<usize, f64>(symbolic, par, Default::default()),
    };
    StackReq::all_of(&[permuted, StackReq::or(StackReq::new::<usize>(n), kernel)])
}

/// `TooLarge` when `need` bytes exceed `have` (a factor of `n` unknowns and `len_val` entries).
fn refuse_beyond(need: u64, have: Option<u64>, n: usize, len_val: usize) -> Result<()> {
    match have {
        Some(have) if need > have => Err(Error::TooLarge {
            what: "memory for the Cholesky factor",
            need,
            have,
            limit: "is available on this machine",
            hint: format!(
                "{n} unknowns, {len_val} entries in the factor: use a coarser mesh (--refine) or a machine with more memory"
            ),
        }),
        _ => Ok(()),
    }
}

/// The fill-reducing ordering of the unknowns of `graph` (position → unknown): nested dissection when
/// `nested` (falling back to AMD where METIS cannot be used), else AMD. See [`super::ordering`].
pub fn fill_order(graph: &Graph, nested: bool) -> Result<Vec<usize>> {
    fill_order_at(graph, None, nested)
}

/// As [`fill_order`], with the nested dissection by coordinate bisection of the vertices at `points`
/// ([`super::dissect`]) instead of METIS's when they are given (and fit the graph).
pub fn fill_order_at(graph: &Graph, points: Option<&[[f64; 2]]>, nested: bool) -> Result<Vec<usize>> {
    if nested {
        if let Some(order) = points.and_then(|p| coordinate_dissection(graph, p)) {
            return Ok(graph.expand(order.into_iter()));
        }
    }
    match if nested { nested_dissection(graph) } else { None } {
        Some((fwd, _)) => Ok(fwd),
        None => amd_order(graph, CholeskySymbolicParams::default().amd_params),
    }
}

/// Σ_j c_j² and Σ_j c_j over the columns j of L's supernodes, c_j the entries of column j on and below
/// the diagonal in its supernode's block (explicit zeros of the relaxed supernodes included).
pub(super) fn flops_and_entries(symbolic: &SymbolicSupernodalCholesky<usize>) -> (f64, f64) {
    let (begin, end, below) = (symbolic.supernode_begin(), symbolic.supernode_end(), symbolic.nnz_per_super());
    let (mut flops, mut entries) = (0.0, 0.0);
    for s in 0..symbolic.n_supernodes() {
        let width = end[s] - begin[s];
        for jj in 0..width {
            let c = (width - jj + below[s]) as f64;
            flops += c * c;
            entries += c;
        }
    }
    (flops, entries)
}

fn is_permutation(p: &[usize]) -> bool {
    let mut seen = vec![false; p.len()];
    p.iter().all(|&i| i < p.len() && !std::mem::replace(&mut seen[i], true))
}

#[cfg(test)]
mod tests {
    use super::refuse_beyond;
    use crate::error::Error;

    /// The system shall refuse a factor larger than the memory there is, naming the sizes, and accept it
    /// when it fits or when the machine does not say what it has.
    #[test]
    fn a_factor_beyond_the_memory_is_refused() {
        assert!(refuse_beyond(10, Some(10), 4, 1).is_ok());
        assert!(refuse_beyond(10, None, 4, 1).is_ok());
        match refuse_beyond(11, Some(10), 4, 1) {
            Err(Error::TooLarge { need: 11, have: 10, hint, .. }) => assert!(hint.contains("4 unknowns")),
            other => panic!("expected TooLarge, got {other:?}"),
        }
    }
}

//! Fill-reducing ordering P: nested dissection for K of [`ND_MIN_SIZE`] unknowns or more ([`METIS_MIN_SIZE`]
//! for a matrix without points), AMD (faer's) below. Why: the factorisation is flop-bound, and on a 2D mesh nested dissection gives the
//! asymptotically optimal fill, O(n log n) entries and O(n^1.5) flops, with a smaller constant than AMD.
//! A run knows its unknowns' points (edge midpoints), so its nested dissection is by coordinate
//! bisection ([`super::dissect`], linear in the unknowns); without points (a matrix alone,
//! [`super::factor::Factor::with_groups`]) METIS_NodeND is used, which costs far more (figures in
//! reference/performance.md). Both order the graph of K with the unknowns of one edge
//! (its two displacement components, numbered consecutively by the space) merged into one (weighted)
//! vertex: this halves the graph and quarters its edges, with the same fill as ordering the full graph
//! (both components of an edge have the same neighbours). The groups are given by the caller; the
//! result is a valid permutation whatever they are (a group per unknown orders the full graph).
//! Deterministic: adjacency lists sorted, a fixed seed, and calls serialised by a lock (METIS
//! draws from the C library's global `rand`), so the same K always gets the same ordering, hence
//! bit-identical results. If METIS cannot be used (tiny or edgeless graphs, indices beyond i32, an
//! error) the ordering falls back to AMD: the ordering only affects speed.

use super::etree::Adjacency;
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::amd;
use faer::sparse::{SparseColMat, SymbolicSparseColMatRef};
use std::sync::Mutex;

/// faer's approximate minimum degree ordering of K (position → unknown), computed on the graph with the
/// groups merged ([`Graph`]; with the two components of an edge as a group): half the vertices and a quarter of the edges of
/// K's graph, so AMD runs about 3× faster for the same fill within a few
/// percent (AMD merges indistinguishable vertices itself, but only after reading the whole graph).
pub(super) fn amd_order(q: &Graph, control: amd::Control) -> Result<Vec<usize>> {
    let ng = q.n_vertices();
    let (mut fwd, mut inv) = (vec![0usize; ng], vec![0usize; ng]);
    let graph = SymbolicSparseColMatRef::new_checked(ng, ng, &q.start, None, &q.adj);
    let mut buf = MemBuffer::try_new(amd::order_scratch::<usize>(ng, q.adj.len()))
        .map_err(|_| Error::Linear("out of memory for the AMD ordering".into()))?;
    amd::order(&mut fwd, &mut inv, graph, control, MemStack::new(&mut buf))
        .map_err(|e| Error::Linear(format!("AMD ordering failed: {e:?}")))?;
    Ok(q.expand(fwd.into_iter()))
}

/// From this many unknowns a run's K (whose unknowns have points) is ordered by the coordinate nested
/// dissection, below by AMD. On Example 5.1 the dissection's factor needs 42 % fewer flops than AMD's at
/// 393,472 unknowns (refine 7: 5.58e10 against 9.59e10; set-up 1.12 s against 1.45 s, peak 11 % lower),
/// 12.5 % fewer at 98,432 (within the set-up's noise there) and 2 % more at 24,640 (reference/performance.md §9).
pub const ND_MIN_SIZE: usize = 200_000;

/// From this many unknowns a matrix without points ([`super::factor::Factor::with_groups`]) is ordered by
/// METIS's nested dissection, below by AMD: METIS costs seconds (1.6 s of CPU at 393,472 unknowns), which
/// the fewer flops repay only on larger matrices.
pub const METIS_MIN_SIZE: usize = 1_000_000;

/// Fixed METIS seed: the ordering, hence every result, is reproducible.
const ND_SEED: i32 = 42;

/// Serialises METIS calls: its random choices come from the C library's global `rand` state, reseeded at
/// each call, so concurrent calls (parallel tests) would interleave their draws and break determinism.
static METIS_LOCK: Mutex<()> = Mutex::new(());

/// The graph of K with the unknowns of one group merged into one vertex (built from K, or from the mesh
/// before K's values exist, see `fem::assemble::EdgePattern`): `first[g]..first[g + 1]` are the
/// unknowns of vertex g (the two components of an edge's displacement, from the space: see
/// [`super::factor::Factor::with_groups`]), and `start`/`adj` the symmetric adjacency of the vertices
/// as compressed rows, sorted, without self loops.
#[derive(Debug, PartialEq)]
pub struct Graph {
    first: Vec<usize>,
    start: Vec<usize>,
    adj: Vec<usize>,
}

impl Graph {
    /// The graph given by its parts: vertex g holds the unknowns `first[g]..first[g + 1]` and is adjacent
    /// to `adj[start[g]..start[g + 1]]` (sorted, symmetric, no self loops); `None` if the parts are not
    /// consistent.
    pub fn new(first: Vec<usize>, start: Vec<usize>, adj: Vec<usize>) -> Option<Graph> {
        let ng = first.len().checked_sub(1)?;
        let ok = first.first() == Some(&0)
            && first.windows(2).all(|w| w[0] < w[1])
            && start.len() == ng + 1
            && start.first() == Some(&0)
            && start.windows(2).all(|w| w[0] <= w[1])
            && start[ng] == adj.len()
            && (0..ng).all(|g| adj[start[g]..start[g + 1]].windows(2).all(|w| w[0] < w[1]))
            && (0..ng).all(|g| adj[start[g]..start[g + 1]].iter().all(|&h| h < ng && h != g));
        ok.then_some(Graph { first, start, adj })
    }

    /// The graph of K with the groups `first` merged.
    pub fn of_matrix(k: &SparseColMat<usize, f64>, first: &[usize]) -> Graph {
        let n = k.nrows();
        let (col_ptr, row_idx) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
        let ng = first.len() - 1;
        let mut group = vec![0usize; n];
        for g in 0..ng {
            group[first[g]..first[g + 1]].iter_mut().for_each(|v| *v = g);
        }
        // symmetric adjacency of the groups, from whichever triangle(s) K stores
        let mut deg = vec![0usize; ng];
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                if group[i] != group[j] {
                    deg[group[i]] += 1;
                    deg[group[j]] += 1;
                }
            }
        }
        let mut raw_start = vec![0usize; ng + 1];
        for g in 0..ng {
            raw_start[g + 1] = raw_start[g] + deg[g];
        }
        drop(deg);
        let mut raw = vec![0usize; raw_start[ng]];
        let mut fill = raw_start[..ng].to_vec();
        for j in 0..n {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                let (gi, gj) = (group[i], group[j]);
                if gi != gj {
                    raw[fill[gi]] = gj;
                    fill[gi] += 1;
                    raw[fill[gj]] = gi;
                    fill[gj] += 1;
                }
            }
        }
        drop(fill);
        let (mut start, mut adj) = (Vec::with_capacity(ng + 1), Vec::with_capacity(raw.len() / 2));
        start.push(0);
        for g in 0..ng {
            let row = &mut raw[raw_start[g]..raw_start[g + 1]];
            row.sort_unstable();
            let mut last = usize::MAX;
            for &h in row.iter() {
                if h != last {
                    adj.push(h);
                    last = h;
                }
            }
            start.push(adj.len());
        }
        Graph { first: first.to_vec(), start, adj }
    }

    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.first.len() - 1
    }

    /// The vertices adjacent to vertex g.
    pub fn neighbours(&self, g: usize) -> &[usize] {
        &self.adj[self.start[g]..self.start[g + 1]]
    }

    /// `first[g]..first[g + 1]`: the unknowns of vertex g.
    pub(super) fn first(&self) -> &[usize] {
        &self.first
    }

    /// The adjacency as compressed rows: `start`, `adj`.
    pub(super) fn adjacency(&self) -> (&[usize], &[usize]) {
        (&self.start, &self.adj)
    }

    /// Unknowns in all.
    pub fn unknowns(&self) -> usize {
        self.first[self.n_vertices()]
    }

    /// The unknowns of the vertices in the order `order` (position → vertex).
    pub(super) fn expand(&self, order: impl Iterator<Item = usize>) -> Vec<usize> {
        let mut fwd = Vec::with_capacity(self.first[self.n_vertices()]);
        for g in order {
            fwd.extend(self.first[g]..self.first[g + 1]);
        }
        fwd
    }
}

/// The pattern of the unknowns a [`Graph`] stands for: unknown k is coupled to the unknowns of its own
/// vertex (itself included) and of the adjacent vertices, every block of two coupled vertices whole, as
/// in K's pattern (`fem::assemble::EdgePattern::unknown_pattern`), so the symbolic factorisation can be
/// computed from the graph without K's pattern ([`super::symbolic::Symbolic::from_graph`]).
pub(super) struct Expanded<'a> {
    graph: &'a Graph,
    /// The vertex of each unknown.
    vertex: Vec<usize>,
    entries: usize,
}

impl Graph {
    /// The pattern of the unknowns it stands for.
    pub(super) fn expanded(&self) -> Expanded<'_> {
        let mut vertex = vec![0usize; self.unknowns()];
        let mut entries = 0;
        let width = |g: usize| self.first[g + 1] - self.first[g];
        for g in 0..self.n_vertices() {
            vertex[self.first[g]..self.first[g + 1]].fill(g);
            entries += width(g) * (width(g) + self.neighbours(g).iter().map(|&h| width(h)).sum::<usize>());
        }
        Expanded { graph: self, vertex, entries }
    }
}

impl Adjacency for Expanded<'_> {
    fn entries(&self) -> usize {
        self.entries
    }

    fn each(&self, j: usize, mut f: impl FnMut(usize)) {
        let (g, first) = (self.vertex[j], &self.graph.first);
        for h in std::iter::once(g).chain(self.graph.neighbours(g).iter().copied()) {
            (first[h]..first[h + 1]).for_each(&mut f);
        }
    }
}

/// Nested-dissection ordering (forward, inverse) of the graph of K by METIS_NodeND, or `None` when
/// METIS cannot be used: the caller then falls back to AMD.
pub(super) fn nested_dissection(q: &Graph) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = q.unknowns();
    let ng = q.n_vertices();
    let mut xadj: Vec<i32> = q.start.iter().map(|&v| i32::try_from(v).ok()).collect::<Option<_>>()?;
    let mut adjncy: Vec<i32> = q.adj.iter().map(|&v| i32::try_from(v).ok()).collect::<Option<_>>()?;
    if adjncy.is_empty() {
        return None;
    }
    let mut vwgt: Vec<i32> = (0..ng).map(|g| (q.first[g + 1] - q.first[g]) as i32).collect();
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut nvtxs = i32::try_from(ng).ok()?;
    let (mut perm, mut iperm) = (vec![0i32; ng], vec![0i32; ng]);
    let status = {
        // poisoned only by a panic of another holder: the lock guards no state (METIS reseeds at each call)
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
    let order: Vec<usize> = perm.iter().map(|&g| usize::try_from(g).ok().filter(|&g| g < ng)).collect::<Option<_>>()?;
    let fwd = q.expand(order.into_iter());
    let mut inv = vec![usize::MAX; n];
    for (new, &old) in fwd.iter().enumerate() {
        inv[old] = new;
    }
    if fwd.len() != n || inv.contains(&usize::MAX) {
        return None;
    }
    Some((fwd, inv))
}

//! Nested dissection by coordinate bisection, for the graph of K on a 2D mesh whose vertices (the
//! edges with unknowns) have points (their midpoints). A set of vertices is split at the median of its
//! points' keys x·d along a direction d; a minimum vertex cover of the edges between the halves
//! ([`super::cover`]) is the separator, ordered after both halves (without it), which are dissected in
//! turn; sets of at most [`LEAF`] vertices are ordered along their longer side. The cover is never
//! larger than either half's vertices adjacent to the other (on Example 5.1 at 1.57 M unknowns, 2.0 %
//! fewer entries of L than those vertices).
//!
//! The direction: sets of 2,000 vertices or more are cut along the direction, among those
//! searched (direction.rs), whose cut has the smallest separator; smaller sets across the
//! longer side of their bounding box. The thickness of a separator depends on the direction of the cut
//! against the mesh: K of Crouzeix–Raviart with the jump term couples the edges of neighbouring
//! triangles, and on Example 5.1's grid of squares cut by one diagonal a cut along an axis needs three
//! edges per square it crosses: 1,535 for the first cut at 1.57 M unknowns, where a cut turned by 30°
//! from the x axis needs 1,319 (of 24 directions tried). METIS finds such cuts too; the search
//! (direction.rs) finds them at about a tenth of its cost (0.7–1.1 s of CPU against 8.1 s). On
//! that matrix the factorisation has 20 % fewer flops (4.53e11 against 5.68e11; METIS's ordering
//! 4.97e11) and L 8 % fewer stored entries (`probes/setup_cost.rs ... nd symbolic`; figures in
//! reference/performance.md §9).
//!
//! Why: on a 2D mesh the straight cut is a separator of O(√n) vertices, as nested dissection needs for
//! its O(n log n) fill, and it costs O(n log n) comparisons in all. METIS_NodeND finds separators of
//! the same kind by multilevel graph partitioning, at a much higher price on these graphs: 1.6 s of
//! CPU at 393,216 unknowns (Example 5.1 refine 7) against about 0.1 s here (`probes/setup_cost.rs`).
//! Any permutation is a valid ordering: the geometry only decides the fill, hence the speed.
//!
//! Deterministic: every choice is made by a total order (coordinate, then vertex number), so the
//! ordering depends only on the graph and the points.

use super::cover;
use super::ordering::Graph;
use std::cmp::Ordering;

/// Sets of at most this many vertices are not dissected further.
const LEAF: usize = 32;

/// The first set of at least this many vertices has its upper half dissected on a second thread, when
/// the thread count in force is 2 or more: the ordering is the same (each half's ordering depends only on
/// its vertices, and the marks each thread compares are its own), and at 1.57 M unknowns the dissection
/// runs beside K's assembly, so the halves share the cores with it (reference/performance.md §9).
const SPLIT_MIN: usize = 100_000;

/// The normals of the cuts across the longer side: x (a cut at x = c) and y.
pub(super) const AXES: [[f64; 2]; 2] = [[1.0, 0.0], [0.0, 1.0]];

/// The longest distance between the points of adjacent vertices of `q` (a little more, for the rounding
/// of the keys): no edge of the graph joins vertices whose keys differ by more.
fn reach(q: &Graph, points: &[[f64; 2]]) -> f64 {
    let mut d2 = 0.0f64;
    for v in 0..q.n_vertices() {
        for &w in q.neighbours(v) {
            let (dx, dy) = (points[v][0] - points[w][0], points[v][1] - points[w][1]);
            d2 = d2.max(dx * dx + dy * dy);
        }
    }
    d2.sqrt() * (1.0 + 1e-9)
}

/// The nested-dissection ordering (position → vertex) of `q`'s vertices at `points`; `None` when the
/// points do not fit the graph (their number, a non-finite coordinate) or the vertices are too many to
/// be numbered in `u32` (as the separators' bipartite graphs number them).
pub fn coordinate_dissection(q: &Graph, points: &[[f64; 2]]) -> Option<Vec<usize>> {
    dissection(q, points, crate::threads::count() > 1)
}

/// As [`coordinate_dissection`], on two threads from the first set of [`SPLIT_MIN`] vertices if `split`.
fn dissection(q: &Graph, points: &[[f64; 2]], split: bool) -> Option<Vec<usize>> {
    let n = q.n_vertices();
    if points.len() != n || n >= u32::MAX as usize || points.iter().flatten().any(|c| !c.is_finite()) {
        return None;
    }
    let mut work = Work {
        q,
        points,
        reach: reach(q, points),
        mark: vec![0; n],
        slot: vec![0; n],
        scratch: Scratch::default(),
        search: Search::default(),
        stamp: 0,
        out: Vec::with_capacity(n),
        split,
    };
    let mut verts: Vec<usize> = (0..n).collect();
    work.dissect(&mut verts);
    Some(work.out)
}

pub(super) struct Work<'a> {
    pub(super) points: &'a [[f64; 2]],
    q: &'a Graph,
    /// The longest distance between the points of adjacent vertices.
    pub(super) reach: f64,
    /// The stamp of the lower half a vertex was last put in (0: a separator's).
    pub(super) mark: Vec<u32>,
    /// Scratch of [`Work::cover`]: a boundary vertex's index in the bipartite graph, and the rest.
    slot: Vec<u32>,
    scratch: Scratch,
    pub(super) search: Search,
    pub(super) stamp: u32,
    out: Vec<usize>,
    /// Whether a set of [`SPLIT_MIN`] vertices or more may still be split between two threads.
    split: bool,
}

/// The buffers of a cut: the vertices near it on either side (what [`Work::cover`] reads) and, for the
/// search of its direction (direction.rs), the points of the set searched and a sample of keys.
#[derive(Default)]
pub(super) struct Search {
    pub(super) lower: Vec<usize>,
    pub(super) upper: Vec<usize>,
    pub(super) at: Vec<[f64; 2]>,
    pub(super) sample: Vec<f64>,
}

/// The buffers of [`Work::cover`], kept from one cut to the next: the vertices of each half adjacent to
/// the other, and the bipartite graph between them as compressed rows.
#[derive(Default)]
struct Scratch {
    a: Vec<usize>,
    b: Vec<usize>,
    ptr: Vec<usize>,
    idx: Vec<u32>,
}

/// The vertices of `half` marked `stamp`, moved to its front: that front.
fn keep_marked<'v>(half: &'v mut [usize], mark: &[u32], stamp: u32) -> &'v mut [usize] {
    let mut kept = 0;
    for i in 0..half.len() {
        if mark[half[i]] == stamp {
            half.swap(i, kept);
            kept += 1;
        }
    }
    &mut half[..kept]
}

impl Work<'_> {
    fn dissect(&mut self, verts: &mut [usize]) {
        let axis = AXES[self.longer_axis(verts)];
        let dir = self.cut_direction(verts, axis);
        let points = self.points;
        let key = |v: usize| points[v][0] * dir[0] + points[v][1] * dir[1];
        let by = |a: &usize, b: &usize| -> Ordering { key(*a).total_cmp(&key(*b)).then(a.cmp(b)) };
        if verts.len() <= LEAF {
            verts.sort_unstable_by(by);
            self.out.extend_from_slice(verts);
            return;
        }
        let m = verts.len() / 2;
        verts.select_nth_unstable_by(m, by);
        self.stamp += 2;
        let s = self.stamp;
        let (lower, upper) = verts.split_at_mut(m);
        lower.iter().for_each(|&v| self.mark[v] = s - 1);
        upper.iter().for_each(|&v| self.mark[v] = s);
        // only vertices within reach of the cut can have a neighbour across it: the cover of the edges
        // across is that of the halves' vertices near it, taken in the halves' order
        let median = key(upper[0]);
        let Search { lower: near_lo, upper: near_up, .. } = &mut self.search;
        near_lo.clear();
        near_lo.extend(lower.iter().copied().filter(|&v| key(v) >= median - self.reach));
        near_up.clear();
        near_up.extend(upper.iter().copied().filter(|&v| key(v) <= median + self.reach));
        let mut separator = self.cover(s);
        separator.iter().for_each(|&v| self.mark[v] = 0);
        let lower = keep_marked(lower, &self.mark, s - 1);
        let upper = keep_marked(upper, &self.mark, s);
        self.dissect_halves(lower, upper);
        separator.sort_unstable_by(by);
        self.out.extend_from_slice(&separator);
    }

    /// The orderings of `lower`, then of `upper`: the upper one on a second thread (with its own copy of
    /// the marks and its own buffers) for the first set of [`SPLIT_MIN`] vertices or more, else in turn.
    fn dissect_halves(&mut self, lower: &mut [usize], upper: &mut [usize]) {
        if !self.split || lower.len() + upper.len() < SPLIT_MIN {
            self.dissect(lower);
            self.dissect(upper);
            return;
        }
        self.split = false;
        let mut other = Work {
            q: self.q,
            points: self.points,
            reach: self.reach,
            mark: self.mark.clone(),
            slot: vec![0; self.slot.len()],
            scratch: Scratch::default(),
            search: Search::default(),
            stamp: self.stamp,
            out: Vec::with_capacity(upper.len()),
            split: false,
        };
        let refused = std::thread::scope(|s| {
            let half = &mut *upper;
            let started = std::thread::Builder::new().spawn_scoped(s, move || {
                other.dissect(half);
                other.out
            });
            self.dissect(lower);
            match started.map(|h| h.join()) {
                Ok(Ok(out)) => self.out.extend(out),
                Ok(Err(e)) => std::panic::resume_unwind(e),
                Err(_) => return true,
            }
            false
        });
        // a thread the system refuses: the upper half here, after the lower one
        if refused {
            self.dissect(upper);
        }
    }

    /// The separator of the vertices near a cut, `self.search.lower` (marked s − 1) and `.upper` (marked
    /// s): a minimum vertex cover of the edges between them (König: from a maximum matching of the
    /// bipartite graph of those edges), so never larger than either side's vertices adjacent to the other.
    pub(super) fn cover(&mut self, s: u32) -> Vec<usize> {
        let (q, mark) = (self.q, &self.mark);
        let Scratch { a, b, ptr, idx } = &mut self.scratch;
        let Search { lower, upper, .. } = &self.search;
        let touching = |half: &[usize], other: u32, out: &mut Vec<usize>| {
            out.clear();
            out.extend(half.iter().copied().filter(|&v| q.neighbours(v).iter().any(|&w| mark[w] == other)));
        };
        touching(lower, s, a);
        touching(upper, s - 1, b);
        for (i, &v) in b.iter().enumerate() {
            self.slot[v] = i as u32;
        }
        // the bipartite graph of the edges from a's vertices to b's (local indices), compressed rows
        ptr.clear();
        idx.clear();
        ptr.push(0);
        for &v in a.iter() {
            idx.extend(q.neighbours(v).iter().filter(|&&w| mark[w] == s).map(|&w| self.slot[w]));
            ptr.push(idx.len());
        }
        let (za, zb) = cover::konig(ptr, idx, b.len());
        let mut separator: Vec<usize> = a.iter().zip(&za).filter(|(_, &r)| !r).map(|(&v, _)| v).collect();
        separator.extend(b.iter().zip(&zb).filter(|(_, &r)| r).map(|(&v, _)| v));
        separator
    }

    /// 0 (x) or 1 (y): the longer side of the points' bounding box.
    fn longer_axis(&self, verts: &[usize]) -> usize {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &v in verts {
            for c in 0..2 {
                lo[c] = lo[c].min(self.points[v][c]);
                hi[c] = hi[c].max(self.points[v][c]);
            }
        }
        usize::from(hi[1] - lo[1] > hi[0] - lo[0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An m × m grid graph (5-point stencil) with its points.
    fn grid(m: usize) -> (Graph, Vec<[f64; 2]>) {
        let (mut start, mut adj) = (vec![0], vec![]);
        for i in 0..m {
            for j in 0..m {
                let mut nb = vec![];
                if i > 0 {
                    nb.push((i - 1) * m + j);
                }
                if j > 0 {
                    nb.push(i * m + j - 1);
                }
                if j + 1 < m {
                    nb.push(i * m + j + 1);
                }
                if i + 1 < m {
                    nb.push((i + 1) * m + j);
                }
                adj.extend(nb);
                start.push(adj.len());
            }
        }
        let points = (0..m * m).map(|v| [(v % m) as f64, (v / m) as f64]).collect();
        (Graph::new((0..=m * m).collect(), start, adj).unwrap(), points)
    }

    #[test]
    fn the_ordering_is_a_permutation_with_separators_last() {
        let (g, p) = grid(40);
        let order = coordinate_dissection(&g, &p).unwrap();
        let mut seen = vec![false; g.n_vertices()];
        assert!(order.iter().all(|&v| !std::mem::replace(&mut seen[v], true)) && seen.iter().all(|&s| s));
        // the first cut (at x = 20, the longer side's median) is ordered last: a vertical line of 40 vertices
        let last: Vec<usize> = order[order.len() - 40..].to_vec();
        let x = p[last[0]][0];
        assert!((x == 19.0 || x == 20.0) && last.iter().all(|&v| p[v][0] == x), "{last:?}");
        // one side of the line whole (760 or 800 vertices), then the other, and no vertex of the first
        // adjacent to one of the second (the separator decouples them)
        let n = g.n_vertices();
        let left = |v: usize| p[v][0] < x;
        let first_left = left(order[0]);
        let k = (0..n).filter(|&v| p[v][0] != x && left(v) == first_left).count();
        assert!(k == 760 || k == 800, "{k}");
        assert!(order[..k].iter().all(|&v| p[v][0] != x && left(v) == first_left));
        assert!(order[k..n - 40].iter().all(|&v| p[v][0] != x && left(v) != first_left));
        let second: std::collections::HashSet<usize> = order[k..n - 40].iter().copied().collect();
        assert!(order[..k].iter().all(|&v| !g.neighbours(v).iter().any(|w| second.contains(w))));
    }

    /// The system shall order last a separator that decouples the halves of the first cut: of the 40
    /// vertices of a maximum matching across it (a minimum cover has as many), no edge left between them.
    #[test]
    fn the_separator_decouples_the_halves() {
        let (g, p) = grid(40);
        let order = coordinate_dissection(&g, &p).unwrap();
        // the last 40 are a vertex cover of the edges across the first cut: removing them leaves no
        // edge between x < 19.5 and x > 19.5
        let sep: std::collections::HashSet<usize> = order[order.len() - 40..].iter().copied().collect();
        let crossing = (0..g.n_vertices())
            .filter(|v| !sep.contains(v) && p[*v][0] < 19.5)
            .any(|v| g.neighbours(v).iter().any(|&w| !sep.contains(&w) && p[w][0] > 19.5));
        assert!(!crossing);
    }

    /// The system shall order a graph the same with the halves of its first large set on two threads as on
    /// one (a 330 × 330 grid: 108,900 vertices, above `SPLIT_MIN`).
    #[test]
    fn two_threads_give_the_same_ordering() {
        let (g, p) = grid(330);
        assert!(g.n_vertices() >= SPLIT_MIN);
        assert_eq!(dissection(&g, &p, true).unwrap(), dissection(&g, &p, false).unwrap());
    }

    #[test]
    fn degenerate_points_still_give_a_permutation() {
        let (g, _) = grid(12);
        let same = vec![[1.0, 1.0]; g.n_vertices()];
        let mut order = coordinate_dissection(&g, &same).unwrap();
        order.sort_unstable();
        assert_eq!(order, (0..g.n_vertices()).collect::<Vec<_>>());
        assert!(coordinate_dissection(&g, &same[1..]).is_none());
        let mut nan = same.clone();
        nan[3][0] = f64::NAN;
        assert!(coordinate_dissection(&g, &nan).is_none());
    }
}

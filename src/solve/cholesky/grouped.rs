//! The elimination tree, the column counts and the permuted upper triangle of K's pattern, computed on
//! the graph of the unknowns' groups ([`Graph`]) instead of on the pattern of the unknowns.
//!
//! Every block of two coupled groups of K is stored whole (`fem::assemble::EdgePattern`), so when the
//! ordering P keeps each group's unknowns together, consecutive and in their own order, L's structure is
//! the groups' structure expanded: with group J at positions P_J … P_J + m_J − 1 and c_J = Σ m_I over the
//! groups I of column J of the groups' factor (J included; the weighted column counts of
//! [`super::etree::column_counts`]),
//!
//! - parent(P_J + k) = P_J + k + 1 for k < m_J − 1, and parent(P_J + m_J − 1) = P_{parent(J)};
//! - c(P_J + k) = c_J − k;
//! - column P_J + k of P K Pᵀ's upper triangle: the unknowns of the groups I < J coupled to J, and
//!   P_J … P_J + k.
//!
//! Why: the groups' graph has half the vertices and a quarter of the entries, so the tree and counts cost
//! a quarter as much (at 1.57 M unknowns the symbolic factorisation went from 0.72 to 0.55 s of CPU,
//! on the critical path of the set-up's phase 1: reference/performance.md §9). The result is the same
//! (`tests`: against the tree, counts and pattern of the expanded graph). With two threads or more (and
//! [`BESIDE_MIN`] unknowns) the unknowns' upper triangle is expanded on a second thread beside the
//! groups' tree and counts (phase 1's main thread is done with K by then). An ordering that splits a
//! group (an unknown of it moved last without the others) is left to the expanded route: `None`.

use super::etree::{column_counts, elimination_tree, postorder, Cols, Pattern, NONE};
use super::ordering::Graph;

/// From this many unknowns the upper triangle is expanded on a second thread: below, the expansion takes
/// a few milliseconds at most and starting a thread (tens of µs) would be paid by every small mesh, as a
/// planner's pilot levels make them by the hundred.
const BESIDE_MIN: usize = 100_000;

/// The permuted upper triangle, the elimination tree and the column counts of the unknowns' pattern.
pub(super) struct Structure {
    pub upper: Pattern,
    pub parent: Vec<usize>,
    pub counts: Vec<usize>,
}

/// The structure of the pattern `graph` stands for under the ordering (fwd, inv) of its unknowns, or
/// `None` when the ordering does not keep every group's unknowns consecutive and in order.
pub(super) fn structure(graph: &Graph, (fwd, inv): (&[usize], &[usize])) -> Option<Structure> {
    let groups = Groups::of(graph, (fwd, inv))?;
    let ng = groups.fwd.len();
    let (gfwd, ginv, at) = (&groups.fwd, &groups.inv, &groups.at);
    // the groups' permuted upper triangle, without the diagonal (the tree does not read it)
    let mut g_upper =
        Pattern { ptr: Vec::with_capacity(ng + 1), idx: Vec::with_capacity(graph.adjacency().1.len() / 2) };
    g_upper.ptr.push(0);
    for &g in gfwd {
        g_upper.idx.extend(graph.neighbours(g).iter().map(|&h| ginv[h]).filter(|&i| i < ginv[g]));
        g_upper.ptr.push(g_upper.idx.len());
    }
    // the unknowns' upper triangle on a second thread (when there are two) beside the groups' tree and counts
    let (upper, (g_parent, g_counts)) = std::thread::scope(|s| {
        let beside = (fwd.len() >= BESIDE_MIN && crate::threads::count() > 1)
            .then(|| std::thread::Builder::new().spawn_scoped(s, || expanded_upper(&g_upper, at)).ok())
            .flatten();
        let g_parent = elimination_tree(&g_upper);
        let (start, adj) = graph.adjacency();
        let width = |j: usize| at[j + 1] - at[j];
        let post = postorder(&g_parent);
        let g_counts = column_counts(&Cols { ptr: start, idx: adj }, (gfwd, ginv), &g_parent, &post, width);
        let upper = match beside.map(|h| h.join()) {
            Some(Ok(upper)) => upper,
            Some(Err(e)) => std::panic::resume_unwind(e),
            None => expanded_upper(&g_upper, at),
        };
        (upper, (g_parent, g_counts))
    });
    let n = fwd.len();
    let (mut parent, mut counts) = (vec![NONE; n], vec![0usize; n]);
    for j in 0..ng {
        let (p, m) = (at[j], at[j + 1] - at[j]);
        for k in 0..m {
            parent[p + k] = match g_parent[j] {
                _ if k + 1 < m => p + k + 1,
                NONE => NONE,
                q => at[q],
            };
            counts[p + k] = g_counts[j] - k;
        }
    }
    Some(Structure { upper, parent, counts })
}

/// The unknowns' permuted upper triangle from the groups' (`at[j]`: the position of group j's first
/// unknown): column P_J + k holds the unknowns of the groups I < J coupled to J, and P_J … P_J + k.
fn expanded_upper(g_upper: &Pattern, at: &[usize]) -> Pattern {
    let ng = at.len() - 1;
    let width = |j: usize| at[j + 1] - at[j];
    let mut upper = Pattern { ptr: Vec::with_capacity(at[ng] + 1), idx: Vec::new() };
    upper.ptr.push(0);
    let entries: usize = (0..ng).map(|j| width(j) * (width(j) + 1) / 2 + width(j) * coupled(g_upper, j, width)).sum();
    upper.idx.reserve_exact(entries);
    for j in 0..ng {
        let p = at[j];
        for k in 0..width(j) {
            for &i in &g_upper.idx[g_upper.ptr[j]..g_upper.ptr[j + 1]] {
                upper.idx.extend(at[i]..at[i + 1]);
            }
            upper.idx.extend(p..=p + k);
            upper.ptr.push(upper.idx.len());
        }
    }
    upper
}

/// The unknowns of the groups before group j coupled to it.
fn coupled(g_upper: &Pattern, j: usize, width: impl Fn(usize) -> usize) -> usize {
    g_upper.idx[g_upper.ptr[j]..g_upper.ptr[j + 1]].iter().map(|&i| width(i)).sum()
}

/// The groups in the order of their unknowns: `fwd` (position → group), `inv` (group → position) and
/// `at[j]` the position of group j's first unknown (`at[ng]` = n).
struct Groups {
    fwd: Vec<usize>,
    inv: Vec<usize>,
    at: Vec<usize>,
}

impl Groups {
    fn of(graph: &Graph, (fwd, inv): (&[usize], &[usize])) -> Option<Groups> {
        let (n, ng, first) = (fwd.len(), graph.n_vertices(), graph.first());
        if inv.len() != n || graph.unknowns() != n {
            return None;
        }
        let mut starting = vec![NONE; n];
        for g in 0..ng {
            let p = inv[first[g]];
            if (first[g]..first[g + 1]).enumerate().any(|(k, u)| inv[u] != p + k) {
                return None;
            }
            starting[p] = g;
        }
        let gfwd: Vec<usize> = starting.into_iter().filter(|&g| g != NONE).collect();
        let mut ginv = vec![0usize; ng];
        let mut at = Vec::with_capacity(ng + 1);
        for (j, &g) in gfwd.iter().enumerate() {
            ginv[g] = j;
            at.push(inv[first[g]]);
        }
        at.push(n);
        Some(Groups { fwd: gfwd, inv: ginv, at })
    }
}

#[cfg(test)]
mod tests {
    use super::super::etree::permuted_upper;
    use super::*;

    /// A random graph of `ng` groups of 1 or 2 unknowns, each coupled to about `per` others.
    fn random_graph(ng: usize, per: usize, seed: u64) -> Graph {
        let mut s = seed;
        let mut next = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 33) as usize
        };
        let mut first = vec![0];
        for _ in 0..ng {
            first.push(first.last().unwrap() + 1 + next() % 2);
        }
        let mut nb = vec![std::collections::BTreeSet::new(); ng];
        for g in 0..ng {
            for _ in 0..per {
                let h = next() % ng;
                if h != g {
                    nb[g].insert(h);
                    nb[h].insert(g);
                }
            }
        }
        let (mut start, mut adj) = (vec![0], vec![]);
        for set in nb {
            adj.extend(set);
            start.push(adj.len());
        }
        Graph::new(first, start, adj).unwrap()
    }

    fn sorted(p: &Pattern) -> Vec<Vec<usize>> {
        (0..p.ptr.len() - 1)
            .map(|j| {
                let mut c = p.idx[p.ptr[j]..p.ptr[j + 1]].to_vec();
                c.sort_unstable();
                c
            })
            .collect()
    }

    /// The system shall compute on the groups the same elimination tree, column counts and permuted upper
    /// triangle as on the expanded pattern of the unknowns, for orderings that keep the groups together.
    #[test]
    fn the_groups_give_the_structure_of_the_unknowns() {
        for (ng, per, seed) in [(1, 0, 1), (7, 1, 2), (60, 2, 3), (400, 3, 4), (900, 5, 5)] {
            let graph = random_graph(ng, per, seed);
            // the groups in a shuffled order, each group's unknowns together
            let mut order: Vec<usize> = (0..ng).collect();
            let mut s = seed;
            for i in (1..ng).rev() {
                s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                order.swap(i, (s >> 33) as usize % (i + 1));
            }
            let fwd = graph.expand(order.into_iter());
            let mut inv = vec![0; fwd.len()];
            fwd.iter().enumerate().for_each(|(p, &u)| inv[u] = p);
            let got = structure(&graph, (&fwd, &inv)).unwrap();
            let upper = permuted_upper(&graph.expanded(), &fwd, &inv);
            let parent = elimination_tree(&upper);
            let counts = column_counts(&graph.expanded(), (&fwd, &inv), &parent, &postorder(&parent), |_| 1);
            assert_eq!(sorted(&got.upper), sorted(&upper), "{ng} groups");
            assert_eq!((got.parent, got.counts), (parent, counts), "{ng} groups");
        }
    }

    /// The system shall leave to the expanded route an ordering that splits a group.
    #[test]
    fn a_split_group_is_refused() {
        let graph = random_graph(50, 2, 9);
        let n = graph.unknowns();
        let two = (0..50).find(|&g| graph.first()[g + 1] - graph.first()[g] == 2).unwrap();
        let u = graph.first()[two];
        // unknown u moved last: its group's other unknown is no longer next to it
        let fwd: Vec<usize> = (0..n).filter(|&v| v != u).chain([u]).collect();
        let mut inv = vec![0; n];
        fwd.iter().enumerate().for_each(|(p, &v)| inv[v] = p);
        assert!(structure(&graph, (&fwd, &inv)).is_none());
    }
}

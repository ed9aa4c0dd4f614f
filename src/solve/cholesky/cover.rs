//! A minimum vertex cover of a bipartite graph (König's theorem), the separator of
//! [`super::dissect`]'s two halves: a maximum matching by augmenting paths (Kuhn's algorithm, its
//! depth-first search iterative, so a long path cannot overflow the stack), then the vertices reached
//! from the unmatched vertices of the first side by alternating paths. The cover is the first side's
//! vertices not reached and the second side's reached; it is never larger than either side.
//!
//! Deterministic: vertices and edges are visited in the order given.

const NONE: u32 = u32::MAX;

/// Of the bipartite graph with first-side vertices `0..ptr.len() - 1` (the edges of vertex a going to the
/// second-side vertices `idx[ptr[a]..ptr[a + 1]]`, each below `nb`), which vertices of each side the alternating paths from
/// the first side's unmatched vertices reach, for a maximum matching: the minimum vertex cover is the
/// first side's vertices not reached and the second side's reached.
pub(super) fn konig(ptr: &[usize], idx: &[u32], nb: usize) -> (Vec<bool>, Vec<bool>) {
    let adj = Rows { ptr, idx };
    let (mate_a, mate_b) = maximum_matching(adj, nb);
    let (mut za, mut zb) = (vec![false; adj.len()], vec![false; nb]);
    let mut stack: Vec<u32> = (0..adj.len() as u32).filter(|&a| mate_a[a as usize] == NONE).collect();
    stack.iter().for_each(|&a| za[a as usize] = true);
    while let Some(a) = stack.pop() {
        for &b in adj.row(a as usize) {
            if !std::mem::replace(&mut zb[b as usize], true) {
                // b is matched, or the matching were not maximum; its mate is reached through it
                let a2 = mate_b[b as usize];
                if a2 != NONE && !std::mem::replace(&mut za[a2 as usize], true) {
                    stack.push(a2);
                }
            }
        }
    }
    (za, zb)
}

/// The first side's edges as compressed rows.
#[derive(Clone, Copy)]
struct Rows<'a> {
    ptr: &'a [usize],
    idx: &'a [u32],
}

impl Rows<'_> {
    fn len(&self) -> usize {
        self.ptr.len() - 1
    }
    fn row(&self, a: usize) -> &[u32] {
        &self.idx[self.ptr[a]..self.ptr[a + 1]]
    }
}

/// A maximum matching (the mate of each vertex of either side, `NONE` if unmatched): a greedy one, then
/// an augmenting path searched from each unmatched first-side vertex.
fn maximum_matching(adj: Rows<'_>, nb: usize) -> (Vec<u32>, Vec<u32>) {
    let (mut mate_a, mut mate_b) = (vec![NONE; adj.len()], vec![NONE; nb]);
    for (a, mate) in mate_a.iter_mut().enumerate() {
        if let Some(&b) = adj.row(a).iter().find(|&&b| mate_b[b as usize] == NONE) {
            *mate = b;
            mate_b[b as usize] = a as u32;
        }
    }
    // a second-side vertex is searched from once per root (`seen` holds the root it was last seen from)
    let mut seen = vec![NONE; nb];
    let mut stack: Vec<(u32, usize)> = Vec::new();
    for root in 0..adj.len() as u32 {
        if mate_a[root as usize] != NONE {
            continue;
        }
        stack.clear();
        stack.push((root, 0));
        while let Some(&mut (a, ref mut next)) = stack.last_mut() {
            let Some(&b) = adj.row(a as usize).get(*next) else {
                stack.pop();
                continue;
            };
            *next += 1;
            if std::mem::replace(&mut seen[b as usize], root) == root {
                continue;
            }
            if mate_b[b as usize] == NONE {
                // augment: each vertex on the path takes the edge it was left by
                for &(a, next) in &stack {
                    let b = adj.row(a as usize)[next - 1];
                    mate_a[a as usize] = b;
                    mate_b[b as usize] = a;
                }
                break;
            }
            stack.push((mate_b[b as usize], 0));
        }
    }
    (mate_a, mate_b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(adj: &[Vec<u32>]) -> (Vec<usize>, Vec<u32>) {
        let ptr = std::iter::once(0)
            .chain(adj.iter().scan(0, |n, r| Some(std::mem::replace(n, *n + r.len()) + r.len())))
            .collect();
        (ptr, adj.concat())
    }

    /// The cover of (first side not reached) ∪ (second side reached).
    fn cover(adj: &[Vec<u32>], nb: usize) -> (Vec<usize>, Vec<usize>) {
        let (ptr, idx) = rows(adj);
        let (za, zb) = konig(&ptr, &idx, nb);
        let a = (0..adj.len()).filter(|&a| !za[a]).collect();
        let b = (0..nb).filter(|&b| zb[b]).collect();
        (a, b)
    }

    /// The system shall find a minimum vertex cover of a bipartite graph: every edge covered, with as many
    /// vertices as a maximum matching has edges (here checked against the sizes known by hand).
    #[test]
    fn the_cover_is_minimum_and_covers_every_edge() {
        // a star: first-side vertex 0 joined to all 5 second-side vertices, the others to none
        let star = vec![vec![0, 1, 2, 3, 4], vec![], vec![]];
        assert_eq!(cover(&star, 5), (vec![0], vec![]));
        // a path a0–b0–a1–b1–a2 (needs an augmenting path after the greedy matching a0–b0, a1–b1... )
        let path = vec![vec![0], vec![0, 1], vec![1]];
        let (a, b) = cover(&path, 2);
        assert_eq!(a.len() + b.len(), 2);
        // a greedy matching a0–b0 leaves a1 (joined to b0 only) to an augmenting path a1–b0–a0–b1
        let aug = vec![vec![0, 1], vec![0]];
        let (ptr, idx) = rows(&aug);
        let (mate_a, _) = maximum_matching(Rows { ptr: &ptr, idx: &idx }, 2);
        assert_eq!(mate_a, vec![1, 0]);
        let (a, b) = cover(&aug, 2);
        assert_eq!(a.len() + b.len(), 2);
        // a 3 × 3 grid-like bipartite graph: every edge covered, cover of the matching's size 3
        let g = vec![vec![0, 1], vec![0, 1, 2], vec![1, 2]];
        let (a, b) = cover(&g, 3);
        assert_eq!(a.len() + b.len(), 3);
        for (x, edges) in g.iter().enumerate() {
            assert!(edges.iter().all(|&y| a.contains(&x) || b.contains(&(y as usize))));
        }
    }
}

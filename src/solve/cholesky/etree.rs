//! The elimination tree and the column counts of the Cholesky factor of P A Pᵀ = L Lᵀ, from A's
//! pattern alone, in O(|A| α(n)) time.
//!
//! With A's pattern permuted (P A Pᵀ, [`permuted_upper`]), L's pattern is described by
//! - the **elimination tree**: parent(j) = min { i > j : L_ij ≠ 0 } (Liu's algorithm with path
//!   compression over the upper triangle, [`elimination_tree`]);
//! - the **column counts** c_j = |{ i ≥ j : L_ij ≠ 0 }| (diagonal included). Row i of L is the row
//!   subtree of the tree: the union of the tree paths from the j < i with A_ij ≠ 0 up to i. Gilbert,
//!   Ng and Peyton count them without walking them: in a postorder of the tree, an entry A_ij makes j
//!   a leaf of row i's subtree when j's first descendant comes after the previous leaf's, and each
//!   leaf adds one to the counts on its path up to the least common ancestor with the previous leaf
//!   (a union–find), so c_j is the sum of the "deltas" over j's subtree ([`column_counts`]).
//!
//! These are T. A. Davis, *Direct Methods for Sparse Linear Systems* (SIAM 2006), §4.1 (`cs_etree`),
//! §4.3 (`cs_post`) and §4.5 (`cs_counts`, `cs_leaf`). faer's own analysis
//! (`factorize_symbolic_cholesky`) counts by walking every row subtree, O(|L|): on a 1.6 M-unknown
//! stiffness |L| is 4.5·10⁸ against |A| = 2.1·10⁷, and that walk was most of the set-up before the
//! numeric factorisation. [`super::symbolic`] gives these to faer's supernodal analysis instead.

use faer::sparse::SymbolicSparseColMatRef;

/// No parent (a root of the elimination forest), no entry yet.
pub const NONE: usize = usize::MAX;

/// A pattern in compressed columns: column j's row indices are `idx[ptr[j]..ptr[j + 1]]`.
pub struct Pattern {
    pub ptr: Vec<usize>,
    pub idx: Vec<usize>,
}

impl Pattern {
    /// A view of it.
    pub fn cols(&self) -> Cols<'_> {
        Cols { ptr: &self.ptr, idx: &self.idx }
    }
}

/// A view of a pattern in compressed columns (a [`Pattern`], or a compact faer pattern's
/// `col_ptr` and `row_idx`).
#[derive(Clone, Copy)]
pub struct Cols<'a> {
    pub ptr: &'a [usize],
    pub idx: &'a [usize],
}

impl<'a> Cols<'a> {
    /// The view of a faer pattern, if it is compact (no separate column lengths).
    pub fn of(pattern: SymbolicSparseColMatRef<'a, usize>) -> Option<Cols<'a>> {
        pattern.col_nnz().is_none().then(|| Cols { ptr: pattern.col_ptr(), idx: pattern.row_idx() })
    }

    fn col(&self, j: usize) -> &'a [usize] {
        &self.idx[self.ptr[j]..self.ptr[j + 1]]
    }
}

/// A symmetric pattern (both triangles) read column by column: stored ([`Cols`]) or the graph of the
/// unknowns' groups expanded (`solve::cholesky::ordering::Graph`), which are the same pattern when the
/// groups' blocks are stored whole (K's pattern, `fem::assemble::EdgePattern`).
pub trait Adjacency {
    /// Entries in all (both triangles, the diagonal once).
    fn entries(&self) -> usize;
    /// `f(i)` for every row i of column j (the diagonal included), in no particular order.
    fn each(&self, j: usize, f: impl FnMut(usize));
}

impl Adjacency for Cols<'_> {
    fn entries(&self) -> usize {
        self.idx.len()
    }

    fn each(&self, j: usize, f: impl FnMut(usize)) {
        self.col(j).iter().copied().for_each(f);
    }
}

/// Both triangles of the symmetric pattern whose lower triangle `pattern` holds (entries above the
/// diagonal are skipped, so both triangles may be stored): column j holds the i with A_ij ≠ 0, in no
/// particular order.
pub fn symmetric(pattern: SymbolicSparseColMatRef<'_, usize>) -> Pattern {
    let n = pattern.ncols();
    let lower = |j: usize| pattern.row_idx_of_col_raw(j).iter().copied().filter(move |&i| i >= j);
    let mut ptr = vec![0usize; n + 1];
    for j in 0..n {
        for i in lower(j) {
            ptr[j + 1] += 1;
            if i > j {
                ptr[i + 1] += 1;
            }
        }
    }
    for j in 0..n {
        ptr[j + 1] += ptr[j];
    }
    let mut at = ptr[..n].to_vec();
    let mut idx = vec![0usize; ptr[n]];
    for j in 0..n {
        for i in lower(j) {
            idx[at[j]] = i;
            at[j] += 1;
            if i > j {
                idx[at[i]] = j;
                at[i] += 1;
            }
        }
    }
    Pattern { ptr, idx }
}

/// The upper triangle of P A Pᵀ from the symmetric pattern `sym` (both triangles, as
/// [`symmetric`] makes it or K's full pattern), `fwd[new] = old` and `inv[old] = new`: column j holds
/// the i ≤ j, made column by column in the new order (written in sequence; faer's supernodal analysis
/// reads each column as a set).
pub fn permuted_upper(sym: &impl Adjacency, fwd: &[usize], inv: &[usize]) -> Pattern {
    let n = fwd.len();
    let mut ptr = Vec::with_capacity(n + 1);
    let mut idx = Vec::with_capacity(sym.entries().div_ceil(2) + n);
    ptr.push(0);
    for (j, &old) in fwd.iter().enumerate() {
        sym.each(old, |i| {
            let i = inv[i];
            if i <= j {
                idx.push(i);
            }
        });
        ptr.push(idx.len());
    }
    Pattern { ptr, idx }
}

/// parent(j) = min { i > j : L_ij ≠ 0 }, or [`NONE`], from the upper triangle (Liu; Davis §4.1):
/// for each entry A_ik, i < k, climb from i through the ancestors found so far (compressing the path
/// to k) until a node without one, whose parent is then k.
pub fn elimination_tree(upper: &Pattern) -> Vec<usize> {
    let n = upper.ptr.len() - 1;
    let (mut parent, mut ancestor) = (vec![NONE; n], vec![NONE; n]);
    for k in 0..n {
        for &i0 in upper.cols().col(k) {
            let mut i = i0;
            while i != NONE && i < k {
                let next = ancestor[i];
                ancestor[i] = k;
                if next == NONE {
                    parent[i] = k;
                }
                i = next;
            }
        }
    }
    parent
}

/// A postorder of the elimination forest (position → node): every node after its descendants,
/// children in increasing order (Davis §4.3, by a depth-first search with an explicit stack).
pub fn postorder(parent: &[usize]) -> Vec<usize> {
    let n = parent.len();
    let (mut head, mut next) = (vec![NONE; n], vec![NONE; n]);
    for j in (0..n).rev() {
        if parent[j] != NONE {
            next[j] = head[parent[j]];
            head[parent[j]] = j;
        }
    }
    let (mut post, mut stack) = (Vec::with_capacity(n), Vec::new());
    for root in (0..n).filter(|&j| parent[j] == NONE) {
        stack.push(root);
        while let Some(&p) = stack.last() {
            match head[p] {
                NONE => {
                    stack.pop();
                    post.push(p);
                }
                child => {
                    head[p] = next[child];
                    stack.push(child);
                }
            }
        }
    }
    post
}

/// c_j, the entries of L's column j (diagonal included), from the symmetric pattern `sym` of A
/// (the rows i > j of P A Pᵀ's column j are the `inv[r]` > j of `sym`'s column `fwd[j]`), the tree
/// and a postorder of it (Gilbert, Ng, Peyton; Davis §4.5). Each row i counts `weight(i)` (1: the
/// entries; a group's unknowns: those of the unknowns, `super::grouped`): its deltas are scaled by it.
pub fn column_counts(
    sym: &impl Adjacency,
    (fwd, inv): (&[usize], &[usize]),
    parent: &[usize],
    post: &[usize],
    weight: impl Fn(usize) -> usize,
) -> Vec<usize> {
    let w = |i: usize| weight(i) as isize;
    let n = parent.len();
    let mut first = vec![NONE; n];
    let mut delta = vec![0isize; n];
    for (k, &p) in post.iter().enumerate() {
        delta[p] = if first[p] == NONE { w(p) } else { 0 };
        let mut j = p;
        while j != NONE && first[j] == NONE {
            first[j] = k;
            j = parent[j];
        }
    }
    let mut leaves = Leaves { first, max_first: vec![NONE; n], prev_leaf: vec![NONE; n], ancestor: (0..n).collect() };
    for &j in post {
        if parent[j] != NONE {
            delta[parent[j]] -= w(j);
        }
        sym.each(fwd[j], |r| {
            let i = inv[r];
            match leaves.leaf(i, j) {
                Leaf::First => delta[j] += w(i),
                Leaf::Subsequent(q) => {
                    delta[j] += w(i);
                    delta[q] -= w(i);
                }
                Leaf::Not => {}
            }
        });
        if parent[j] != NONE {
            leaves.ancestor[j] = parent[j];
        }
    }
    for j in 0..n {
        if parent[j] != NONE {
            delta[parent[j]] += delta[j];
        }
    }
    delta.into_iter().map(|d| d as usize).collect()
}

/// Whether j is a leaf of row i's subtree, and if it is a subsequent one, the least common ancestor
/// q of j and the previous leaf (whose count the overlap must not add twice).
enum Leaf {
    Not,
    First,
    Subsequent(usize),
}

/// The state of `cs_leaf` (Davis §4.5): first[j] the postorder position of j's first descendant,
/// max_first[i] the largest first[j] seen for row i, prev_leaf[i] its previous leaf, and `ancestor`
/// the union–find forest of the nodes already visited.
struct Leaves {
    first: Vec<usize>,
    max_first: Vec<usize>,
    prev_leaf: Vec<usize>,
    ancestor: Vec<usize>,
}

impl Leaves {
    fn leaf(&mut self, i: usize, j: usize) -> Leaf {
        if i <= j || (self.max_first[i] != NONE && self.first[j] <= self.max_first[i]) {
            return Leaf::Not;
        }
        self.max_first[i] = self.first[j];
        let prev = std::mem::replace(&mut self.prev_leaf[i], j);
        if prev == NONE {
            return Leaf::First;
        }
        let mut q = prev;
        while q != self.ancestor[q] {
            q = self.ancestor[q];
        }
        let mut s = prev;
        while s != q {
            let up = self.ancestor[s];
            self.ancestor[s] = q;
            s = up;
        }
        Leaf::Subsequent(q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::cholesky::simplicial::{
        prefactorize_symbolic_cholesky, prefactorize_symbolic_cholesky_scratch,
    };
    use faer::sparse::SymbolicSparseColMat;

    /// A symmetric pattern (both triangles, diagonal included) of n unknowns with about `per` random
    /// off-diagonal entries a column, the last `isolated` unknowns coupled to nothing (a forest).
    fn random_pattern(n: usize, per: usize, isolated: usize, seed: u64) -> SymbolicSparseColMat<usize> {
        let mut s = seed;
        let mut next = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 33) as usize
        };
        let coupled = n - isolated;
        let mut cols: Vec<Vec<usize>> = (0..n).map(|j| vec![j]).collect();
        for j in 0..coupled {
            for _ in 0..per {
                let i = next() % coupled;
                cols[j].push(i);
                cols[i].push(j);
            }
        }
        let (mut ptr, mut idx) = (vec![0], Vec::new());
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            idx.extend(c);
            ptr.push(idx.len());
        }
        SymbolicSparseColMat::new_checked(n, n, ptr, None, idx)
    }

    /// faer's elimination tree (as usize, NONE for a root) and column counts of the pattern `upper`.
    fn faer_counts(upper: &Pattern) -> (Vec<usize>, Vec<usize>) {
        let n = upper.ptr.len() - 1;
        let a = SymbolicSparseColMatRef::new_unsorted_checked(n, n, &upper.ptr, None, &upper.idx);
        let (mut etree, mut counts) = (vec![0isize; n], vec![0usize; n]);
        let mut mem = MemBuffer::new(prefactorize_symbolic_cholesky_scratch::<usize>(n, upper.idx.len()));
        prefactorize_symbolic_cholesky(&mut etree, &mut counts, a, MemStack::new(&mut mem));
        (etree.iter().map(|&p| if p < 0 { NONE } else { p as usize }).collect(), counts)
    }

    /// The system shall compute the elimination tree and the column counts of L exactly as faer's
    /// row-subtree walk does, on random patterns under random orderings, forests included.
    #[test]
    fn tree_and_counts_agree_with_faers_walk() {
        for (seed, (n, per, isolated)) in [(200, 2, 0), (500, 3, 7), (1000, 1, 40), (64, 8, 1)].into_iter().enumerate()
        {
            let pattern = random_pattern(n, per, isolated, seed as u64 + 1);
            let mut inv: Vec<usize> = (0..n).collect();
            let mut s = 977 * (seed + 1);
            for i in (1..n).rev() {
                s = (s * 1103515245 + 12345) % 2147483648;
                inv.swap(i, s % (i + 1));
            }
            let mut fwd = vec![0; n];
            inv.iter().enumerate().for_each(|(old, &new)| fwd[new] = old);
            let sym = symmetric(pattern.as_ref());
            let upper = permuted_upper(&sym.cols(), &fwd, &inv);
            let parent = elimination_tree(&upper);
            let post = postorder(&parent);
            let mut seen = vec![false; n];
            for (k, &j) in post.iter().enumerate() {
                seen[j] = true;
                assert!(parent[j] == NONE || post[k + 1..].contains(&parent[j]), "postorder: {j} after its parent");
            }
            assert!(seen.iter().all(|&s| s), "the postorder visits every node");
            let counts = column_counts(&sym.cols(), (&fwd, &inv), &parent, &post, |_| 1);
            let (faer_parent, faer_counts) = faer_counts(&upper);
            assert_eq!(parent, faer_parent, "elimination tree, n = {n}");
            assert_eq!(counts, faer_counts, "column counts, n = {n}");
        }
    }
}

//! Numbering the edges {a, b} of a mesh by their vertex pair, without hashing: an edge lives in the
//! bucket of its smaller vertex a, which holds the (b, value) pairs of the edges found so far. A vertex
//! has a few edges, so a lookup scans a few pairs; the buckets are sized once, from the keys that may be
//! inserted (each key counted at every occurrence). It replaced a `HashMap` whose hashing and growth
//! were a third of building the mesh, on the single thread that starts a run.

/// The sides of triangle `t`, side i opposite its vertex i.
pub fn sides(t: &[usize; 3]) -> [[usize; 2]; 3] {
    [[t[1], t[2]], [t[2], t[0]], [t[0], t[1]]]
}

/// Values (edge numbers, midpoint vertices) of vertex pairs, bucketed by the smaller vertex.
pub struct EdgeIndex {
    /// Bucket a is `pairs[start[a]..start[a] + len[a]]`, with room up to `start[a + 1]`.
    start: Vec<usize>,
    len: Vec<u32>,
    pairs: Vec<(usize, usize)>,
}

impl EdgeIndex {
    /// An empty index for vertices `0..n_vertices` with room for `keys`, every pair that may be
    /// inserted, counted at each occurrence (for example every side of every triangle).
    pub fn with_room(n_vertices: usize, keys: impl Iterator<Item = [usize; 2]>) -> EdgeIndex {
        let mut start = vec![0usize; n_vertices + 1];
        for [a, b] in keys {
            start[a.min(b)] += 1;
        }
        let mut sum = 0;
        for s in start.iter_mut() {
            let c = *s;
            *s = sum;
            sum += c;
        }
        EdgeIndex { start, len: vec![0; n_vertices], pairs: vec![(0, 0); sum] }
    }

    /// The value of the pair {a, b}, if inserted.
    pub fn get(&self, a: usize, b: usize) -> Option<usize> {
        let (lo, hi) = (a.min(b), a.max(b));
        if lo >= self.len.len() {
            return None;
        }
        let s = self.start[lo];
        self.pairs[s..s + self.len[lo] as usize].iter().find(|p| p.0 == hi).map(|p| p.1)
    }

    /// The value of the pair {a, b}; if it is new, `make()` is inserted as its value first. Panics if the
    /// pair is beyond the room given to [`EdgeIndex::with_room`].
    pub fn get_or_insert_with(&mut self, a: usize, b: usize, make: impl FnOnce() -> usize) -> usize {
        let (lo, hi) = (a.min(b), a.max(b));
        let (s, n) = (self.start[lo], self.len[lo] as usize);
        if let Some(p) = self.pairs[s..s + n].iter().find(|p| p.0 == hi) {
            return p.1;
        }
        assert!(s + n < self.start[lo + 1], "EdgeIndex: more pairs than the room given");
        let v = make();
        self.pairs[s + n] = (hi, v);
        self.len[lo] += 1;
        v
    }
}

#[cfg(test)]
mod tests {
    use super::EdgeIndex;

    #[test]
    fn numbers_pairs_in_order_of_first_insertion_either_way_round() {
        let keys = [[0, 1], [1, 2], [2, 0], [1, 0], [2, 3], [3, 1], [1, 2]];
        let mut index = EdgeIndex::with_room(4, keys.iter().copied());
        let mut next = 0;
        let got: Vec<usize> = keys
            .iter()
            .map(|&[a, b]| {
                index.get_or_insert_with(a, b, || {
                    next += 1;
                    next - 1
                })
            })
            .collect();
        assert_eq!(got, [0, 1, 2, 0, 3, 4, 1]);
        assert_eq!((index.get(3, 2), index.get(0, 3), index.get(9, 0)), (Some(3), None, None));
    }
}

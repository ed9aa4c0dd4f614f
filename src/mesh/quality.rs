//! Mesh diagnostics for messages: pieces without a Dirichlet edge, slivers.

use super::Mesh;

impl Mesh {
    /// A point of the first piece of the mesh (triangles connected through edges) none of whose edges
    /// satisfies `fixed`: such a piece floats (rigid motions free). For the messages of an ill-conditioned K.
    pub fn floating_piece(&self, fixed: impl Fn(usize) -> bool) -> Option<[f64; 2]> {
        let mut piece = vec![usize::MAX; self.tris.len()];
        for start in 0..self.tris.len() {
            if piece[start] != usize::MAX {
                continue;
            }
            let (mut stack, mut held) = (vec![start], false);
            piece[start] = start;
            while let Some(t) = stack.pop() {
                for &e in &self.tri_edges[t] {
                    held |= fixed(e);
                    let (a, b) = self.edge_tris[e];
                    for n in [Some(a), b].into_iter().flatten() {
                        if piece[n] == usize::MAX {
                            piece[n] = start;
                            stack.push(n);
                        }
                    }
                }
            }
            if !held {
                return Some(self.points[self.tris[start][0]]);
            }
        }
        None
    }

    /// The largest aspect ratio (longest edge / height on it) of a triangle, and where.
    pub fn worst_aspect(&self) -> (f64, [f64; 2]) {
        let mut worst = (0.0, [0.0; 2]);
        for (t, tri) in self.tris.iter().enumerate() {
            let l = self.tri_edges[t].iter().map(|&e| self.edge_length(e)).fold(0.0, f64::max);
            let r = l * l / (2.0 * self.area(t)).max(f64::MIN_POSITIVE);
            if r > worst.0 {
                worst = (r, self.points[tri[0]]);
            }
        }
        worst
    }
}

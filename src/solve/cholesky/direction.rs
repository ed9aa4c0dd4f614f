//! The direction of a cut of the coordinate dissection (`super::dissect`): of directions spread over a
//! half turn, the one whose cut through the median has the smallest separator. On a 2D mesh the
//! thickness of a separator depends on the direction of the cut against the mesh (the module doc of
//! `super::dissect` gives Example 5.1's figures); the search costs a pass over the set and a cover near
//! the cut for each direction tried.
//!
//! Deterministic: the directions and their order are fixed, ties keep the earlier one.

use super::dissect::{Search, Work, AXES};

/// Sets of at least this many vertices are cut across the direction, of [`ANGLES`], with the thinnest
/// separator ([`Work::thinnest_cut`]); smaller ones across the longer side of their bounding box.
const SEARCH_MIN: usize = 2000;

/// The directions of the cuts searched: evenly spread over a half turn, the axes among them.
const ANGLES: usize = 8;

/// Refinements of the best direction, each turning it by ± half the last step.
const REFINE: usize = 1;

/// The median of a cut searched is that of every `SAMPLE`-th vertex's key.
const SAMPLE: usize = 16;

/// The unit normal at angle t to the x axis, the axes exactly.
fn direction(t: f64) -> [f64; 2] {
    if t == 0.0 {
        AXES[0]
    } else if t == std::f64::consts::FRAC_PI_2 {
        AXES[1]
    } else {
        [t.cos(), t.sin()]
    }
}

impl Work<'_> {
    /// The normal of the cut of `verts`: [`Work::thinnest_cut`] for sets of [`SEARCH_MIN`] vertices or
    /// more, else `axis` (across the longer side of their bounding box).
    pub(super) fn cut_direction(&mut self, verts: &[usize], axis: [f64; 2]) -> [f64; 2] {
        if verts.len() >= SEARCH_MIN {
            self.thinnest_cut(verts, axis)
        } else {
            axis
        }
    }

    /// The normal of the cut through the median with the smallest separator, among directions searched
    /// coarse to fine: `axis`, then the [`ANGLES`] spread evenly over a half turn, then [`REFINE`] times
    /// the best so far turned by ± half the last step. Each is estimated by [`Work::cut_estimate`]; a
    /// direction replaces the best only with a smaller separator, so ties keep `axis`.
    fn thinnest_cut(&mut self, verts: &[usize], axis: [f64; 2]) -> [f64; 2] {
        let mut at = std::mem::take(&mut self.search.at);
        at.clear();
        at.extend(verts.iter().map(|&v| self.points[v]));
        let best = self.thinnest_cut_at(verts, &at, axis);
        self.search.at = at;
        best
    }

    fn thinnest_cut_at(&mut self, verts: &[usize], at: &[[f64; 2]], axis: [f64; 2]) -> [f64; 2] {
        let mut best = (self.cut_estimate(verts, at, axis), axis, f64::NAN);
        let step = std::f64::consts::PI / ANGLES as f64;
        for i in 0..ANGLES {
            let t = step * i as f64;
            let dir = direction(t);
            if dir != axis {
                let size = self.cut_estimate(verts, at, dir);
                if size < best.0 {
                    best = (size, dir, t);
                }
            }
        }
        let mut half = step / 2.0;
        for _ in 0..REFINE {
            let t0 = if best.2.is_nan() {
                if axis == AXES[0] {
                    0.0
                } else {
                    std::f64::consts::FRAC_PI_2
                }
            } else {
                best.2
            };
            for t in [t0 - half, t0 + half] {
                let dir = direction(t);
                let size = self.cut_estimate(verts, at, dir);
                if size < best.0 {
                    best = (size, dir, t);
                }
            }
            half /= 2.0;
        }
        best.1
    }

    /// The size of the separator of the cut of `verts` with normal `dir` through the median of every
    /// [`SAMPLE`]-th key: the cover of the edges across it, which join only vertices within
    /// [`Work::reach`] of it.
    fn cut_estimate(&mut self, verts: &[usize], at: &[[f64; 2]], dir: [f64; 2]) -> usize {
        let key = |p: &[f64; 2]| p[0] * dir[0] + p[1] * dir[1];
        let Search { sample, lower, upper, .. } = &mut self.search;
        sample.clear();
        sample.extend(at.iter().step_by(SAMPLE).map(key));
        let m = sample.len() / 2;
        let median = *sample.select_nth_unstable_by(m, f64::total_cmp).1;
        let (lo, hi) = (median - self.reach, median + self.reach);
        lower.clear();
        upper.clear();
        for (&v, p) in verts.iter().zip(at) {
            let k = key(p);
            if k >= lo && k < median {
                lower.push(v);
            } else if k >= median && k <= hi {
                upper.push(v);
            }
        }
        self.stamp += 2;
        let s = self.stamp;
        lower.iter().for_each(|&v| self.mark[v] = s - 1);
        upper.iter().for_each(|&v| self.mark[v] = s);
        self.cover(s).len()
    }
}

#[cfg(test)]
mod tests {
    use super::super::dissect::coordinate_dissection;
    use super::super::ordering::Graph;
    use super::*;

    /// An m × m grid graph of the 9-point stencil (diagonal neighbours too) with its points.
    fn king(m: usize) -> (Graph, Vec<[f64; 2]>) {
        let (mut start, mut adj) = (vec![0], vec![]);
        for i in 0..m as i64 {
            for j in 0..m as i64 {
                for (di, dj) in [(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)] {
                    let (a, b) = (i + di, j + dj);
                    if (0..m as i64).contains(&a) && (0..m as i64).contains(&b) {
                        adj.push(a as usize * m + b as usize);
                    }
                }
                start.push(adj.len());
            }
        }
        let points = (0..m * m).map(|v| [(v % m) as f64, (v / m) as f64]).collect();
        (Graph::new((0..=m * m).collect(), start, adj).unwrap(), points)
    }

    /// The system shall cut a large set along the direction of its thinnest separator, not only across
    /// the longer side of its bounding box: on a 60 × 60 grid of the 9-point stencil turned by 22.5°, the
    /// first cut follows a grid line, 60 vertices that split the rest in two halves, where a cut across
    /// an axis needs a staircase of about 60 (1 + tan 22.5°) ≈ 85 (a diagonal neighbour crosses each step).
    #[test]
    fn a_large_set_is_cut_along_its_thinnest_separator() {
        let m = 60;
        let (g, p) = king(m);
        assert!(g.n_vertices() >= SEARCH_MIN);
        let (c, s) = (22.5f64.to_radians().cos(), 22.5f64.to_radians().sin());
        let turned: Vec<[f64; 2]> = p.iter().map(|q| [c * q[0] - s * q[1], s * q[0] + c * q[1]]).collect();
        let order = coordinate_dissection(&g, &turned).unwrap();
        let n = g.n_vertices();
        let sep: std::collections::HashSet<usize> = order[n - m..].iter().copied().collect();
        // the components of the grid without those 60 vertices: two, of nearly half the vertices each
        let mut comp = vec![usize::MAX; n];
        let mut sizes = Vec::new();
        for v0 in (0..n).filter(|v| !sep.contains(v)) {
            if comp[v0] != usize::MAX {
                continue;
            }
            let (mut stack, mut size) = (vec![v0], 0);
            comp[v0] = sizes.len();
            while let Some(v) = stack.pop() {
                size += 1;
                for &w in g.neighbours(v) {
                    if !sep.contains(&w) && comp[w] == usize::MAX {
                        comp[w] = sizes.len();
                        stack.push(w);
                    }
                }
            }
            sizes.push(size);
        }
        sizes.sort_unstable();
        assert!(sizes.len() == 2 && sizes[0] >= (n - m) * 2 / 5, "{sizes:?}");
    }
}

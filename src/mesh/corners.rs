//! The boundary points where a solution may be singular: polygon corners (an interior angle ω ≠ π) and the
//! points where two boundary edges of different parts meet.
//!
//! The interior angle at a boundary vertex is the sum of the angles its triangles make there, so it is
//! found without ordering the boundary, on any mesh the builder accepts. A vertex where the boundary
//! touches itself (more than two boundary edges) is reported with its two first edges.

use super::Mesh;

/// Angles within this of π are straight (a structured mesh's boundary vertices carry rounding only).
const STRAIGHT: f64 = 1e-9;

/// A boundary vertex at a corner or a change of part.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryPoint {
    pub vertex: usize,
    pub point: [f64; 2],
    /// The interior angle ω in (0, 2π].
    pub angle: f64,
    /// The two boundary edges that meet there.
    pub edges: [usize; 2],
}

impl Mesh {
    /// Every boundary vertex whose interior angle differs from π or whose two boundary edges satisfy
    /// `differ` (for example: they belong to parts of different kinds), in vertex order.
    pub fn boundary_points(&self, differ: impl Fn(usize, usize) -> bool) -> Vec<BoundaryPoint> {
        let mut angle = vec![0.0; self.points.len()];
        for t in &self.tris {
            for i in 0..3 {
                let (a, b, c) = (self.points[t[i]], self.points[t[(i + 1) % 3]], self.points[t[(i + 2) % 3]]);
                let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
                angle[t[i]] += (u[0] * v[1] - u[1] * v[0]).atan2(u[0] * v[0] + u[1] * v[1]);
            }
        }
        let mut at: Vec<Vec<usize>> = vec![Vec::new(); self.points.len()];
        for (e, &(_, other)) in self.edge_tris.iter().enumerate() {
            if other.is_none() {
                for v in self.edges[e] {
                    at[v].push(e);
                }
            }
        }
        at.iter()
            .enumerate()
            .filter(|(_, es)| es.len() >= 2)
            .filter(|&(v, es)| (angle[v] - std::f64::consts::PI).abs() > STRAIGHT || differ(es[0], es[1]))
            .map(|(v, es)| BoundaryPoint { vertex: v, point: self.points[v], angle: angle[v], edges: [es[0], es[1]] })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Diagonal, MeshSpec};
    use std::f64::consts::PI;

    #[test]
    fn a_square_has_four_right_angles_and_a_change_of_part() {
        let spec = MeshSpec::Structured {
            corners: [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]],
            cells: [4, 2],
            diagonal: Diagonal::First,
            refine: 1,
        };
        let m = Mesh::from_spec(&spec).unwrap();
        let corners = m.boundary_points(|_, _| false);
        assert_eq!(corners.len(), 4);
        assert!(corners.iter().all(|c| (c.angle - PI / 2.0).abs() < 1e-12));
        // a change of part at (1, 0), the middle of the bottom side, is a straight boundary point
        let mid = |e: usize| m.midpoint(e);
        let split =
            m.boundary_points(|a, b| mid(a)[1] == 0.0 && mid(b)[1] == 0.0 && (mid(a)[0] < 1.0) != (mid(b)[0] < 1.0));
        let extra: Vec<_> = split.iter().filter(|c| (c.angle - PI).abs() < 1e-12).collect();
        assert_eq!(extra.len(), 1);
        assert_eq!(extra[0].point, [1.0, 0.0]);
    }
}

//! Conforming local refinement by newest-vertex bisection (NVB) with completion, and Dörfler marking.
//!
//! Convention: vertex 0 of a triangle is its *newest vertex*, and its *refinement edge* is the opposite
//! side t[1]t[2] (so `Mesh::tri_edges[t][0]`, which `Mesh::build` keeps: it only swaps t[1] and t[2]).
//! Bisecting (v0; v1, v2) at the midpoint m of v1v2 gives the children (m; v0, v1) and (m; v2, v0), both
//! counter-clockwise when the parent is, each with its newest vertex m and a side of the parent as
//! refinement edge. The initial labelling ([`label_longest_edge`]) takes each triangle's longest side.
//!
//! One refinement step (Binev–Dahmen–DeVore 2004; Stevenson 2008, "The completion of locally refined
//! simplicial partitions created by bisection"): mark the refinement edge of every marked triangle, then
//! close: an edge marked in one triangle marks the refinement edge of every triangle containing it, until
//! nothing changes (a worklist over edges, so O(edges)). Each triangle is then cut 1, 2, 3 or 4 times:
//! bisected if its refinement edge is marked, and each child bisected again if its refinement edge (a
//! side of the parent) is marked. Every marked edge is then split in both triangles beside it, so the
//! result is conforming; the children lie inside their parent (nested meshes: `fem::prolong` applies).
//! Every triangle produced by NVB from an initial triangle T is similar to one of finitely many
//! triangles (at most 4 classes per T, Sewell 1972, Mitchell 1991), so the minimum angle is bounded
//! below by the minimum over the first generations of uniform bisection of T: [`descendant_min_angle`].
//! A boundary edge that is split passes its tag to both halves.

use super::{Mesh, RawMesh};

/// Reorder each triangle so that vertex 0 is opposite its longest side (ties: the first longest side in
/// the order t[1]t[2], t[2]t[0], t[0]t[1]); the cyclic order, hence the orientation, is kept.
pub fn label_longest_edge(raw: &mut RawMesh) {
    let pts = &raw.points;
    for t in raw.tris.iter_mut() {
        let len2 = |a: usize, b: usize| {
            let (p, q) = (pts[a], pts[b]);
            (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
        };
        let l = [len2(t[1], t[2]), len2(t[2], t[0]), len2(t[0], t[1])];
        let i = (0..3).fold(0, |best, i| if l[i] > l[best] { i } else { best });
        *t = [t[i], t[(i + 1) % 3], t[(i + 2) % 3]];
    }
}

/// The mesh as raw data (triangles in their order, tagged boundary edges), for refining it again.
pub fn to_raw(mesh: &Mesh) -> RawMesh {
    let tagged = (0..mesh.edges.len()).filter_map(|e| mesh.edge_tag[e].map(|tag| (mesh.edges[e], tag))).collect();
    RawMesh {
        source: mesh.source.clone(),
        points: mesh.points.clone(),
        tris: mesh.tris.clone(),
        tagged,
        tag_names: mesh.tag_names.clone(),
    }
}

/// The edges to split so that bisecting the `marked` triangles leaves a conforming mesh: the refinement
/// edges of the marked triangles, closed under "an edge marked in a triangle marks its refinement edge".
pub fn closure(mesh: &Mesh, marked: &[bool]) -> Vec<bool> {
    let mut split = vec![false; mesh.edges.len()];
    let mut work = Vec::new();
    for (t, _) in marked.iter().enumerate().filter(|(_, m)| **m) {
        let e = mesh.tri_edges[t][0];
        if !split[e] {
            split[e] = true;
            work.push(e);
        }
    }
    while let Some(e) = work.pop() {
        let (t1, t2) = mesh.edge_tris[e];
        for t in std::iter::once(t1).chain(t2) {
            let r = mesh.tri_edges[t][0];
            if !split[r] {
                split[r] = true;
                work.push(r);
            }
        }
    }
    split
}

/// One NVB step: bisect the `marked` triangles of `mesh` (vertex 0 newest) and as many others as
/// conformity needs. Returns the refined mesh and, per new triangle, its parent in `mesh`.
pub fn bisect(mesh: &Mesh, marked: &[bool]) -> (RawMesh, Vec<usize>) {
    let split = closure(mesh, marked);
    let mut points = mesh.points.clone();
    let mut mid = vec![usize::MAX; mesh.edges.len()];
    for (e, _) in split.iter().enumerate().filter(|(_, s)| **s) {
        mid[e] = points.len();
        let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
        points.push([0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
    }
    let mut tris = Vec::with_capacity(mesh.tris.len() + 2 * split.iter().filter(|s| **s).count());
    let mut parent = Vec::with_capacity(tris.capacity());
    for (t, &[v0, v1, v2]) in mesh.tris.iter().enumerate() {
        let [e0, e1, e2] = mesh.tri_edges[t];
        if !split[e0] {
            tris.push([v0, v1, v2]);
        } else {
            let m = mid[e0];
            // child (m; v0, v1), refinement edge v0v1 = e2; child (m; v2, v0), refinement edge v2v0 = e1
            for (child, e) in [([m, v0, v1], e2), ([m, v2, v0], e1)] {
                if split[e] {
                    let [c0, c1, c2] = child;
                    tris.push([mid[e], c0, c1]);
                    tris.push([mid[e], c2, c0]);
                } else {
                    tris.push(child);
                }
            }
        }
        parent.resize(tris.len(), t);
    }
    let mut tagged = Vec::new();
    for e in 0..mesh.edges.len() {
        if let Some(tag) = mesh.edge_tag[e] {
            let [a, b] = mesh.edges[e];
            if split[e] {
                tagged.push(([a, mid[e]], tag));
                tagged.push(([mid[e], b], tag));
            } else {
                tagged.push(([a, b], tag));
            }
        }
    }
    let raw = RawMesh { source: mesh.source.clone(), points, tris, tagged, tag_names: mesh.tag_names.clone() };
    (raw, parent)
}

/// Dörfler's marking: the fewest triangles, largest indicators first, whose squared indicators `eta2`
/// sum to at least θ of the total (0 < θ ≤ 1). Ties at the threshold are marked too, so the marking
/// does not depend on the order of equal indicators.
pub fn dorfler(eta2: &[f64], theta: f64) -> Vec<bool> {
    let mut order: Vec<usize> = (0..eta2.len()).collect();
    order.sort_by(|&a, &b| eta2[b].total_cmp(&eta2[a]));
    let total: f64 = eta2.iter().sum();
    let mut marked = vec![false; eta2.len()];
    let (mut sum, mut last) = (0.0, f64::INFINITY);
    for &t in &order {
        if sum >= theta * total && eta2[t] < last {
            break;
        }
        sum += eta2[t];
        last = eta2[t];
        marked[t] = true;
    }
    marked
}

/// The smallest interior angle of triangle `p`, in degrees.
pub fn triangle_min_angle(p: [[f64; 2]; 3]) -> f64 {
    (0..3)
        .map(|i| {
            let (a, b, c) = (p[i], p[(i + 1) % 3], p[(i + 2) % 3]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
            let cross = (u[0] * v[1] - u[1] * v[0]).abs();
            cross.atan2(u[0] * v[0] + u[1] * v[1]).to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}

impl Mesh {
    /// The smallest interior angle over all triangles, in degrees.
    pub fn min_angle(&self) -> f64 {
        self.tris.iter().map(|t| triangle_min_angle(t.map(|v| self.points[v]))).fold(f64::INFINITY, f64::min)
    }
}

/// The smallest angle (degrees) among the descendants of triangle `t` (vertex 0 newest) over
/// `generations` uniform bisections: NVB's lower bound for the descendants of `t` once `generations`
/// covers its similarity classes (4 suffice; module doc).
pub fn descendant_min_angle(t: [[f64; 2]; 3], generations: usize) -> f64 {
    let mut level = vec![t];
    let mut min = triangle_min_angle(t);
    for _ in 0..generations {
        level = level
            .iter()
            .flat_map(|&[v0, v1, v2]| {
                let m = [0.5 * (v1[0] + v2[0]), 0.5 * (v1[1] + v2[1])];
                [[m, v0, v1], [m, v2, v0]]
            })
            .collect();
        min = level.iter().map(|&p| triangle_min_angle(p)).fold(min, f64::min);
    }
    min
}

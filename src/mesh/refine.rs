//! Uniform red refinement: every triangle is split into four by its edge midpoints; a tagged boundary
//! edge becomes two edges with the same tag.

use super::edge_index::{sides, EdgeIndex};
use super::RawMesh;

/// One red refinement of `raw`.
pub fn red(raw: &RawMesh) -> RawMesh {
    let mut points = raw.points.clone();
    let keys = raw.tris.iter().flat_map(sides).chain(raw.tagged.iter().map(|t| t.0));
    let mut mid = EdgeIndex::with_room(raw.points.len(), keys);
    let mut midpoint = |a: usize, b: usize, points: &mut Vec<[f64; 2]>| -> usize {
        mid.get_or_insert_with(a, b, || {
            let (p, q) = (points[a], points[b]);
            points.push([0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]);
            points.len() - 1
        })
    };
    let mut tris = Vec::with_capacity(4 * raw.tris.len());
    for &[a, b, c] in &raw.tris {
        let ab = midpoint(a, b, &mut points);
        let bc = midpoint(b, c, &mut points);
        let ca = midpoint(c, a, &mut points);
        tris.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    let mut tagged = Vec::with_capacity(2 * raw.tagged.len());
    for &([a, b], tag) in &raw.tagged {
        let m = midpoint(a, b, &mut points);
        tagged.push(([a, m], tag));
        tagged.push(([m, b], tag));
    }
    RawMesh { source: raw.source.clone(), points, tris, tagged, tag_names: raw.tag_names.clone() }
}

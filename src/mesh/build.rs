//! [`Mesh::build`]: a [`RawMesh`]'s triangles oriented counter-clockwise and checked, its edges and their
//! adjacency made, and its tagged boundary elements bound to edges.

use super::edge_index::{sides, EdgeIndex};
use super::{area2, Mesh, RawMesh};
use crate::error::{Error, Result};

/// The edges of a mesh: their vertices, the triangles beside each (the second `None` on the boundary),
/// the edges of each triangle, and the index from a vertex pair to its edge.
struct Edges {
    index: EdgeIndex,
    edges: Vec<[usize; 2]>,
    edge_tris: Vec<(usize, Option<usize>)>,
    tri_edges: Vec<[usize; 3]>,
}

impl Mesh {
    /// Build edges and adjacency, orient triangles counter-clockwise, and validate.
    pub fn build(raw: RawMesh) -> Result<Mesh> {
        let src = raw.source.as_str();
        if raw.tris.is_empty() {
            return Err(Error::mesh(src, "no triangles"));
        }
        let mut tris = raw.tris.clone();
        for (k, t) in tris.iter_mut().enumerate() {
            orient(&raw, k, t)?;
        }
        let Edges { index, edges, edge_tris, tri_edges } = connect(&raw, &tris)?;
        check_no_overlap(&raw, &tris, &edges, &edge_tris)?;
        let edge_tag = tag_edges(&raw, &index, &edge_tris)?;
        Ok(Mesh {
            source: raw.source,
            points: raw.points,
            tris,
            edges,
            tri_edges,
            edge_tris,
            edge_tag,
            tag_names: raw.tag_names,
        })
    }
}

/// Check triangle `k` (its vertices exist, its size is representable in f64, its area is not zero)
/// and turn it counter-clockwise.
fn orient(raw: &RawMesh, k: usize, t: &mut [usize; 3]) -> Result<()> {
    let src = raw.source.as_str();
    if t.iter().any(|&v| v >= raw.points.len()) {
        return Err(Error::mesh(src, format!("triangle {k} refers to a missing vertex")));
    }
    let [a, b, c] = t.map(|v| raw.points[v]);
    let a2 = area2(a, b, c);
    let scale = [(a, b), (b, c), (c, a)].iter().map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1])).fold(0.0, f64::max);
    if !(scale * scale).is_finite() {
        return Err(Error::mesh(
            src,
            format!(
                "triangle {k} at ({:e}, {:e}) has edges of {scale:.1e}: its area overflows f64 (beyond \
                 1.8e308); give the mesh in smaller units (the answer scales with them)",
                a[0], a[1]
            ),
        ));
    }
    if scale > 0.0 && scale * scale < 1e4 * f64::MIN_POSITIVE {
        return Err(Error::mesh(
            src,
            format!(
                "triangle {k} at ({:e}, {:e}) has edges of {scale:.1e}: its area is beyond the normal range of f64; \
                 give the mesh in larger units (the answer scales with them)",
                a[0], a[1]
            ),
        ));
    }
    if a2.abs().partial_cmp(&(1e-12 * scale * scale)) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::mesh(src, format!("triangle {k} at ({:.6}, {:.6}) is degenerate (zero area)", a[0], a[1])));
    }
    if a2 < 0.0 {
        t.swap(1, 2);
    }
    Ok(())
}

/// The edges of the triangles `tris` and their adjacency (an error for an edge of three triangles).
fn connect(raw: &RawMesh, tris: &[[usize; 3]]) -> Result<Edges> {
    let mut index = EdgeIndex::with_room(raw.points.len(), tris.iter().flat_map(sides));
    // about 3/2 edges a triangle
    let mut edges = Vec::with_capacity(tris.len() * 3 / 2 + 2);
    let mut edge_tris: Vec<(usize, Option<usize>)> = Vec::with_capacity(edges.capacity());
    let mut tri_edges = Vec::with_capacity(tris.len());
    for (k, t) in tris.iter().enumerate() {
        let mut te = [0; 3];
        for (i, [a, b]) in sides(t).into_iter().enumerate() {
            let key = [a.min(b), a.max(b)];
            let e = index.get_or_insert_with(a, b, || {
                edges.push(key);
                edge_tris.push((k, None));
                edges.len() - 1
            });
            if edge_tris[e].0 != k {
                if edge_tris[e].1.is_some() {
                    let p = raw.points[a];
                    return Err(Error::mesh(
                        raw.source.as_str(),
                        format!(
                            "edge at ({:.6}, {:.6}) is shared by more than two triangles (non-manifold)",
                            p[0], p[1]
                        ),
                    ));
                }
                edge_tris[e].1 = Some(k);
            }
            te[i] = e;
        }
        tri_edges.push(te);
    }
    Ok(Edges { index, edges, edge_tris, tri_edges })
}

/// Refuse overlapping (inverted) neighbours: the opposite vertices must lie on opposite sides of the edge.
fn check_no_overlap(
    raw: &RawMesh,
    tris: &[[usize; 3]],
    edges: &[[usize; 2]],
    edge_tris: &[(usize, Option<usize>)],
) -> Result<()> {
    for (e, &(t1, t2)) in edge_tris.iter().enumerate() {
        if let Some(t2) = t2 {
            let [a, b] = edges[e].map(|v| raw.points[v]);
            let opp = |t: usize| {
                tris[t].iter().copied().find(|v| !edges[e].contains(v)).expect("triangle has a third vertex")
            };
            let s1 = area2(a, b, raw.points[opp(t1)]);
            let s2 = area2(a, b, raw.points[opp(t2)]);
            // signs, not the product s1·s2, which underflows to 0 on a mesh of size ~1e-150
            if s1 == 0.0 || s2 == 0.0 || (s1 > 0.0) == (s2 > 0.0) {
                return Err(Error::mesh(
                    raw.source.as_str(),
                    format!(
                        "triangles {t1} and {t2} overlap across the edge at ({:.6}, {:.6}) (inverted element)",
                        a[0], a[1]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The tag of every edge from the raw mesh's tagged boundary elements (`None` untagged): each must be a
/// boundary edge, in one part.
fn tag_edges(raw: &RawMesh, index: &EdgeIndex, edge_tris: &[(usize, Option<usize>)]) -> Result<Vec<Option<usize>>> {
    let src = raw.source.as_str();
    let mut edge_tag = vec![None; edge_tris.len()];
    for &(pair, tag) in &raw.tagged {
        let key = [pair[0].min(pair[1]), pair[0].max(pair[1])];
        let p = raw.points.get(key[0]).copied().unwrap_or([f64::NAN; 2]);
        let Some(e) = index.get(key[0], key[1]) else {
            return Err(Error::mesh(
                src,
                format!(
                    "boundary element at ({:.6}, {:.6}) of part `{}` is not an edge of any triangle",
                    p[0], p[1], raw.tag_names[tag]
                ),
            ));
        };
        if edge_tris[e].1.is_some() {
            return Err(Error::mesh(
                src,
                format!(
                    "interior edge at ({:.6}, {:.6}) is tagged as boundary part `{}`",
                    p[0], p[1], raw.tag_names[tag]
                ),
            ));
        }
        match edge_tag[e] {
            Some(old) if old != tag => {
                return Err(Error::mesh(
                    src,
                    format!(
                        "boundary edge at ({:.6}, {:.6}) is in two parts: `{}` and `{}`",
                        p[0], p[1], raw.tag_names[old], raw.tag_names[tag]
                    ),
                ))
            }
            _ => edge_tag[e] = Some(tag),
        }
    }
    Ok(edge_tag)
}

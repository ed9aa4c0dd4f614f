//! Triangle meshes: vertices, counter-clockwise triangles, edges, edge↔triangle adjacency, and the
//! boundary part of every boundary edge.
//!
//! Built from a [`RawMesh`] (points, triangles, tagged boundary edges) produced by the structured
//! generator or the Gmsh reader, after optional red refinement. [`Mesh::build`] rejects degenerate and
//! overlapping triangles, non-manifold edges and tags on interior edges; [`Mesh::bind_parts`] checks
//! that every boundary edge belongs to exactly one declared part. [`bisect`] refines locally;
//! [`Mesh::boundary_points`] finds the corners and changes of part, where a solution may be singular.

pub mod bisect;
mod build;
mod corners;
pub use corners::BoundaryPoint;
mod edge_index;
mod gmsh;
mod quality;
pub(crate) mod refine;
mod structured;

use crate::error::{Error, Result};
use serde::Deserialize;
use std::path::PathBuf;

pub use gmsh::parse as parse_gmsh;
pub use structured::generate as structured_raw;

/// Direction of the diagonal splitting each structured cell.
#[derive(Deserialize, Clone, Copy, PartialEq, Eq, Debug)]
#[serde(rename_all = "lowercase")]
pub enum Diagonal {
    /// Cell (i, j) split along p(i, j)–p(i+1, j+1).
    First,
    /// Cell (i, j) split along p(i+1, j)–p(i, j+1).
    Second,
}

/// Where the mesh comes from.
#[derive(Clone, Debug)]
pub enum MeshSpec {
    /// Quadrilateral c0 c1 c2 c3 (counter-clockwise), n × m cells, each split by one diagonal.
    Structured { corners: [[f64; 2]; 4], cells: [usize; 2], diagonal: Diagonal, refine: u32 },
    /// Gmsh 4.1 ASCII file, `refine` red refinements.
    Gmsh { path: PathBuf, refine: u32 },
}

/// Mesh data before topology is built: points, triangles and tagged boundary edges.
#[derive(Clone, Debug)]
pub struct RawMesh {
    /// Name used in messages (file name or "structured mesh").
    pub source: String,
    pub points: Vec<[f64; 2]>,
    pub tris: Vec<[usize; 3]>,
    /// Boundary edges (vertex pairs) with an index into `tag_names`.
    pub tagged: Vec<([usize; 2], usize)>,
    pub tag_names: Vec<String>,
}

/// A validated triangle mesh with edge topology.
#[derive(Clone, Debug)]
pub struct Mesh {
    pub source: String,
    pub points: Vec<[f64; 2]>,
    /// Counter-clockwise vertex triples.
    pub tris: Vec<[usize; 3]>,
    /// Vertex pairs.
    pub edges: Vec<[usize; 2]>,
    /// `tri_edges[t][i]` is the edge opposite local vertex i of triangle t.
    pub tri_edges: Vec<[usize; 3]>,
    /// The one or two triangles sharing an edge.
    pub edge_tris: Vec<(usize, Option<usize>)>,
    /// Tag of each boundary edge (index into `tag_names`); `None` for interior edges.
    pub edge_tag: Vec<Option<usize>>,
    pub tag_names: Vec<String>,
}

/// Twice the signed area of (a, b, c).
pub fn area2(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

/// The raw mesh a scene describes, refined as asked (before topology is built).
pub fn raw_from_spec(spec: &MeshSpec) -> Result<RawMesh> {
    Ok(match spec {
        MeshSpec::Structured { corners, cells, diagonal, refine } => {
            let f = 1usize << refine;
            structured::generate(corners, [cells[0] * f, cells[1] * f], *diagonal)?
        }
        MeshSpec::Gmsh { path, refine } => {
            let mut raw = gmsh::read(path)?;
            for _ in 0..*refine {
                raw = refine::red(&raw);
            }
            raw
        }
    })
}

impl Mesh {
    /// Generate or read the mesh a scene describes, refined as asked.
    pub fn from_spec(spec: &MeshSpec) -> Result<Mesh> {
        Mesh::build(raw_from_spec(spec)?)
    }

    /// Index in `parts` (the scene's boundary part names) of every boundary edge (`None` for interior
    /// edges). Every boundary edge must be in a declared part, and every declared part must have edges.
    pub fn bind_parts(&self, parts: &[&str]) -> Result<Vec<Option<usize>>> {
        let src = self.source.as_str();
        let tag_to_part: Vec<Option<usize>> =
            self.tag_names.iter().map(|n| parts.iter().position(|p| p == n)).collect();
        let mut out = vec![None; self.edges.len()];
        let mut count = vec![0usize; parts.len()];
        for (e, slot) in out.iter_mut().enumerate() {
            if self.edge_tris[e].1.is_some() {
                continue;
            }
            let m = self.midpoint(e);
            let tag = self.edge_tag[e].ok_or_else(|| {
                Error::mesh(src, format!("boundary edge at ({:.6}, {:.6}) belongs to no boundary part", m[0], m[1]))
            })?;
            let p = tag_to_part[tag].ok_or_else(|| {
                Error::mesh(
                    src,
                    format!(
                        "boundary part `{}` of the mesh is not declared in the scene ([[boundary]] name = \"{}\")",
                        self.tag_names[tag], self.tag_names[tag]
                    ),
                )
            })?;
            count[p] += 1;
            *slot = Some(p);
        }
        for (p, c) in parts.iter().zip(&count) {
            if *c == 0 {
                let known = self.tag_names.join(", ");
                return Err(Error::mesh(
                    src,
                    format!("scene part `{p}` has no boundary edges in the mesh (mesh parts: {known})"),
                ));
            }
        }
        Ok(out)
    }

    /// Midpoint of edge e.
    pub fn midpoint(&self, e: usize) -> [f64; 2] {
        let [a, b] = self.edges[e].map(|v| self.points[v]);
        [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]
    }

    /// Length of edge e.
    pub fn edge_length(&self, e: usize) -> f64 {
        let [a, b] = self.edges[e].map(|v| self.points[v]);
        (b[0] - a[0]).hypot(b[1] - a[1])
    }

    /// Outward unit normal of boundary edge e (outward from its one triangle).
    pub fn outward_normal(&self, e: usize) -> [f64; 2] {
        let t = self.edge_tris[e].0;
        let [a, b] = self.edges[e].map(|v| self.points[v]);
        let len = self.edge_length(e);
        let n = [(b[1] - a[1]) / len, -(b[0] - a[0]) / len];
        let opp = self.tris[t].iter().copied().find(|v| !self.edges[e].contains(v)).expect("third vertex");
        let c = self.points[opp];
        let d = [c[0] - a[0], c[1] - a[1]];
        if n[0] * d[0] + n[1] * d[1] > 0.0 {
            [-n[0], -n[1]]
        } else {
            n
        }
    }

    /// Area of triangle t.
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.tris[t].map(|v| self.points[v]);
        0.5 * area2(a, b, c)
    }
    /// Largest edge length (the mesh size h).
    pub fn h_max(&self) -> f64 {
        (0..self.edges.len()).map(|e| self.edge_length(e)).fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(n: usize) -> Mesh {
        let c = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]];
        Mesh::from_spec(&MeshSpec::Structured { corners: c, cells: [n, n], diagonal: Diagonal::First, refine: 0 })
            .unwrap()
    }

    #[test]
    fn euler_characteristic_and_edge_count() {
        for n in [1, 2, 5] {
            let m = square(n);
            assert_eq!(m.tris.len(), 2 * n * n);
            assert_eq!(m.edges.len(), 3 * n * n + 2 * n);
            assert_eq!(m.points.len() + m.tris.len() - m.edges.len(), 1);
            let boundary = m.edge_tris.iter().filter(|e| e.1.is_none()).count();
            assert_eq!(boundary, 4 * n);
            assert!(m.edge_tag.iter().zip(&m.edge_tris).all(|(t, e)| t.is_some() == e.1.is_none()));
        }
    }

    #[test]
    fn outward_normals_point_out() {
        let m = square(3);
        for e in 0..m.edges.len() {
            if m.edge_tris[e].1.is_none() {
                let n = m.outward_normal(e);
                let p = m.midpoint(e);
                let q = [p[0] + 0.1 * n[0], p[1] + 0.1 * n[1]];
                assert!(q[0] < 0.0 || q[0] > 4.0 || q[1] < 0.0 || q[1] > 4.0);
            }
        }
    }

    #[test]
    fn red_refinement_quadruples() {
        let c = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let raw = structured::generate(&c, [2, 2], Diagonal::First).unwrap();
        let fine = Mesh::build(refine::red(&raw)).unwrap();
        assert_eq!(fine.tris.len(), 32);
        assert_eq!(fine.edges.len(), 3 * 16 + 8);
        let total: f64 = (0..fine.tris.len()).map(|t| fine.area(t)).sum();
        assert!((total - 1.0).abs() < 1e-14);
    }

    #[test]
    fn degenerate_and_nonmanifold_are_rejected() {
        let raw = RawMesh {
            source: "t".into(),
            points: vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]],
            tris: vec![[0, 1, 2]],
            tagged: vec![],
            tag_names: vec![],
        };
        assert!(Mesh::build(raw).unwrap_err().to_string().contains("degenerate"));
        let raw = RawMesh {
            source: "t".into(),
            points: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0], [0.0, -1.0]],
            tris: vec![[0, 1, 2], [1, 3, 2], [0, 4, 1], [0, 1, 3]],
            tagged: vec![],
            tag_names: vec![],
        };
        assert!(Mesh::build(raw).unwrap_err().to_string().contains("non-manifold"));
    }
}

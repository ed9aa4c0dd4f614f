//! The quadrature points of the loads: Dunavant degree 4 in every triangle for the body force, 3-point
//! Gauss on the edges of every Neumann or contact part with a traction.

use super::LoadPoint;
use crate::fem::quadrature::{edge_point, tri_point, GAUSS3, TRI4};
use crate::fem::space::{CrSpace, Element};
use crate::mesh::Mesh;
use crate::scene::expr::Vec2Expr;
use crate::scene::{PartKind, Scene};

/// Each load of `scene` (the body force if any, then every Neumann part with a traction) with its
/// quadrature points.
pub(super) fn load_points<'a>(scene: &'a Scene, mesh: &Mesh, space: &CrSpace) -> Vec<(&'a Vec2Expr, Vec<LoadPoint>)> {
    let mut raw = Vec::new();
    if let Some(f) = &scene.f {
        raw.push((f, body_points(mesh)));
    }
    for (p, part) in scene.parts.iter().enumerate() {
        let g = match &part.kind {
            PartKind::Neumann(g) => g.as_ref(),
            PartKind::Contact(c) => c.traction.as_ref(),
            PartKind::Dirichlet(_) => None,
        };
        if let Some(g) = g {
            raw.push((g, traction_points(mesh, space, p)));
        }
    }
    raw
}

/// The points of the body force: Dunavant degree 4 in every triangle.
fn body_points(mesh: &Mesh) -> Vec<LoadPoint> {
    let mut points = Vec::with_capacity(6 * mesh.tris.len());
    for t in 0..mesh.tris.len() {
        let el = Element::new(mesh, t);
        for (l, w) in TRI4 {
            let phi = Element::phi(l);
            let wt = w * el.area;
            let edges = [0, 1, 2].map(|i| (mesh.tri_edges[t][i], wt * phi[i]));
            points.push(LoadPoint { x: tri_point(el.pts, l), edges });
        }
    }
    points
}

/// The points of the traction of part `p`: 3-point Gauss on each of its edges.
fn traction_points(mesh: &Mesh, space: &CrSpace, p: usize) -> Vec<LoadPoint> {
    let mut points = Vec::new();
    for e in 0..mesh.edges.len() {
        if space.edge_part[e] != Some(p) {
            continue;
        }
        let t = mesh.edge_tris[e].0;
        let el = Element::new(mesh, t);
        let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
        let len = mesh.edge_length(e);
        for (s, w) in GAUSS3 {
            let x = edge_point(a, b, s);
            let phi = Element::phi(el.bary(x));
            let edges = [0, 1, 2].map(|i| (mesh.tri_edges[t][i], w * len * phi[i]));
            points.push(LoadPoint { x, edges });
        }
    }
    points
}

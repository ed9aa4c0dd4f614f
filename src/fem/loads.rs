//! The load functional t ↦ lⁿ on the unknowns of V_h:
//!   (lⁿ, v) = ∫_Ω f(tₙ)·v (Dunavant degree 4) + Σ_{Neumann e} ∫_e g(tₙ)·v (3-point Gauss).
//! Quadrature points and the weights w·φ feeding each unknown are stored once, so each step evaluates the
//! (compiled) load expressions at all points of a term in one batch, then scatters sequentially.

use super::quadrature::{edge_point, tri_point, GAUSS3, TRI4};
use super::space::{CrSpace, Element};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::{BoundSet, ExprSet, Vec2Expr};
use crate::scene::{PartKind, Scene};

/// A quadrature point of a load term: position, and the (edge, weight · φ) pairs it feeds.
#[derive(Clone, Debug)]
struct LoadPoint {
    x: [f64; 2],
    edges: [(usize, f64); 3],
}

/// One contribution of a point's value v: `out[slot] += w · (c·v)`.
#[derive(Clone, Copy, Debug)]
struct Scatter {
    slot: usize,
    w: f64,
    c: [f64; 2],
}

/// Precomputed quadrature for one vector load (body force or one Neumann part).
#[derive(Clone, Debug)]
struct LoadTerm {
    /// Both components, compiled together and bound to the quadrature points.
    expr: BoundSet,
    /// The contributions of point i: `scatter[first[i]..first[i + 1]]`.
    first: Vec<usize>,
    scatter: Vec<Scatter>,
}

/// The load functional t ↦ l(t) on the unknowns.
#[derive(Clone, Debug)]
pub struct Loads {
    terms: Vec<LoadTerm>,
    n_dofs: usize,
    /// The unknowns any load can touch, increasing (all of them with a body force, only boundary ones
    /// with tractions alone).
    support: Vec<usize>,
}

impl Loads {
    /// Quadrature points of the body force (if any) and of every Neumann part with a traction.
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Loads {
        let mut raw: Vec<(&Vec2Expr, Vec<LoadPoint>)> = Vec::new();
        if let Some(f) = &scene.f {
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
            raw.push((f, points));
        }
        for (p, part) in scene.parts.iter().enumerate() {
            let PartKind::Neumann(Some(g)) = &part.kind else {
                continue;
            };
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
            raw.push((g, points));
        }
        let mut touched = vec![false; space.n_dofs];
        for p in raw.iter().flat_map(|t| &t.1) {
            for &(e, _) in &p.edges {
                for (k, _) in space.edge_dof[e].terms() {
                    touched[k] = true;
                }
            }
        }
        let support: Vec<usize> = (0..space.n_dofs).filter(|&k| touched[k]).collect();
        let mut slot = vec![usize::MAX; space.n_dofs];
        for (i, &k) in support.iter().enumerate() {
            slot[k] = i;
        }
        let terms = raw
            .into_iter()
            .map(|(e, pts)| {
                let mut first = vec![0];
                let mut scatter = Vec::new();
                for p in &pts {
                    for &(e, w) in &p.edges {
                        scatter.extend(space.edge_dof[e].terms().map(|(k, c)| Scatter { slot: slot[k], w, c }));
                    }
                    first.push(scatter.len());
                }
                let points = pts.iter().map(|p| p.x).collect();
                LoadTerm { expr: ExprSet::new(&[&e.0[0], &e.0[1]]).bind(points), first, scatter }
            })
            .collect();
        Loads { terms, n_dofs: space.n_dofs, support }
    }

    /// The unknowns a load can be nonzero on (increasing).
    pub fn support(&self) -> &[usize] {
        &self.support
    }

    /// l(t) restricted to [`Loads::support`], into `out`.
    pub fn assemble_on_support(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        out.resize(self.support.len(), 0.0);
        let mut values = Vec::new();
        for term in &self.terms {
            // the expression values in parallel batches, the sums sequentially: bit-identical results
            term.expr.eval(t, &mut values)?;
            for (i, v) in values.chunks_exact(2).enumerate() {
                for s in &term.scatter[term.first[i]..term.first[i + 1]] {
                    out[s.slot] += s.w * (s.c[0] * v[0] + s.c[1] * v[1]);
                }
            }
        }
        Ok(())
    }

    /// Scatter values on the support into a full vector of unknowns.
    pub fn expand(&self, on_support: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.resize(self.n_dofs, 0.0);
        for (&k, &v) in self.support.iter().zip(on_support) {
            out[k] = v;
        }
    }

    /// l(t) into `out` (length = number of unknowns).
    pub fn assemble(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let mut s = Vec::new();
        self.assemble_on_support(t, &mut s)?;
        self.expand(&s, out);
        Ok(())
    }
}

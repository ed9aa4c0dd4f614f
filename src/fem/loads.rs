//! The load functional t ↦ lⁿ on the unknowns of V_h:
//!   (lⁿ, v) = ∫_Ω f(tₙ)·v (Dunavant degree 4) + Σ_{Neumann e} ∫_e g(tₙ)·v (3-point Gauss).
//! Quadrature points and the weights w·φ feeding each unknown are stored once, so each step evaluates the
//! (compiled) load expressions at all points of a term in one batch, then scatters sequentially.
//!
//! Storage is what a time node streams through memory, so it is compact: the points of one triangle
//! (or one Neumann edge) feed the same three edges, stored once per such group; per point only its three
//! weights w·φᵢ; the unknowns and vector coefficients of an edge come from one table shared by all terms.
//! The sums are those of a plain point-by-point scatter, in the same order (the same bits).

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

/// Precomputed quadrature for one vector load (body force or one Neumann part).
#[derive(Clone, Debug)]
struct LoadTerm {
    /// Both components, compiled together and bound to the quadrature points.
    expr: BoundSet,
    /// Consecutive points feeding the same three edges: the edges and the number of points.
    groups: Vec<([u32; 3], u32)>,
    /// Per point: the weight w·φᵢ of each of its group's edges.
    weights: Vec<[f64; 3]>,
}

thread_local! {
    /// The expression values of a term, kept from one time node to the next (megabytes on fine meshes).
    static SCRATCH: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// The load functional t ↦ l(t) on the unknowns.
#[derive(Clone, Debug)]
pub struct Loads {
    terms: Vec<LoadTerm>,
    /// The (support slot, vector coefficient) pairs of edge e: `edge_terms[edge_first[e]..edge_first[e + 1]]`.
    edge_first: Vec<u32>,
    edge_terms: Vec<(u32, [f64; 2])>,
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
        let mut edge_first = vec![0u32];
        let mut edge_terms = Vec::new();
        for dof in &space.edge_dof {
            edge_terms.extend(dof.terms().map(|(k, c)| (slot[k] as u32, c)));
            edge_first.push(edge_terms.len() as u32);
        }
        let terms = raw
            .into_iter()
            .map(|(e, pts)| {
                let mut groups: Vec<([u32; 3], u32)> = Vec::new();
                for p in &pts {
                    let edges = p.edges.map(|(e, _)| e as u32);
                    match groups.last_mut() {
                        Some((g, n)) if *g == edges => *n += 1,
                        _ => groups.push((edges, 1)),
                    }
                }
                let weights = pts.iter().map(|p| p.edges.map(|(_, w)| w)).collect();
                let points = pts.iter().map(|p| p.x).collect();
                LoadTerm { expr: ExprSet::new(&[&e.0[0], &e.0[1]]).bind(points), groups, weights }
            })
            .collect();
        Loads { terms, edge_first, edge_terms, n_dofs: space.n_dofs, support }
    }

    /// The unknowns a load can be nonzero on (increasing).
    pub fn support(&self) -> &[usize] {
        &self.support
    }

    /// l(t) restricted to [`Loads::support`], into `out`.
    pub fn assemble_on_support(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        out.resize(self.support.len(), 0.0);
        SCRATCH.with(|cell| {
            // a nested call on this thread (none today) would get a buffer of its own
            let mut own = Vec::new();
            let mut borrowed = cell.try_borrow_mut();
            let values = borrowed.as_deref_mut().unwrap_or(&mut own);
            for term in &self.terms {
                // the expression values in parallel batches, the sums sequentially: bit-identical results
                term.expr.eval(t, values)?;
                let mut points = values.chunks_exact(2).zip(&term.weights);
                for &(edges, n) in &term.groups {
                    let terms = edges.map(|e| {
                        &self.edge_terms[self.edge_first[e as usize] as usize..self.edge_first[e as usize + 1] as usize]
                    });
                    for (v, w) in points.by_ref().take(n as usize) {
                        for (terms, w) in terms.iter().zip(w) {
                            for &(slot, c) in *terms {
                                out[slot as usize] += w * (c[0] * v[0] + c[1] * v[1]);
                            }
                        }
                    }
                }
            }
            Ok(())
        })
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

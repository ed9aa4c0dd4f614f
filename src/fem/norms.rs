//! True errors against an exact solution u (with its exact gradient — never finite differences):
//!
//! * energy: |||u − u_h|||² = Σ_T ∫_T σ(u − u_h):ε(u − u_h) + Σ_{e ∈ interior ∪ Dirichlet} (2ρμ/h_e) ∫_e |[u_h]|²
//!   (the exact u is continuous and vanishes on Γ_D, so the jump of the error is the jump of u_h),
//! * broken H¹ seminorm |u − u_h|_{1,h} and L² norm ‖u − u_h‖,
//!
//! by the degree-4 triangle rule and the exact 2-point edge rule. The exact u and ∇u (six expressions,
//! bound to the quadrature points: separated in time or compiled, see [`super::exact`]) are evaluated
//! chunk of elements by chunk of elements, each
//! chunk's values used at once while they are in the processor's cache (not written out for the whole
//! mesh and read back). Chunks run in parallel; the per-element contributions are summed in element
//! order, so the norms are bit-identical for any thread count.

use super::elasticity::Elasticity;
use super::exact::{ExactAt, VALUES};
use super::quadrature::{tri_point, GAUSS2, TRI4};
use super::space::{jump_terms, CrSpace, Element};
use crate::error::Error;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::program::LANES;
use crate::scene::Exact;
use std::sync::Mutex;

/// Elements per chunk of work: their 6 points each make whole batches of [`LANES`] points, and their
/// values (36 per element) stay in the first-level cache.
const CHUNK_ELEMENTS: usize = 2 * LANES;

/// The three error norms at one time.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ErrorNorms {
    pub energy: f64,
    pub h1: f64,
    pub l2: f64,
}

impl ErrorNorms {
    /// Componentwise maximum.
    pub fn max(self, o: ErrorNorms) -> ErrorNorms {
        ErrorNorms { energy: self.energy.max(o.energy), h1: self.h1.max(o.h1), l2: self.l2.max(o.l2) }
    }
}

/// Precomputed geometry for repeated error evaluation.
pub struct ErrorEvaluator {
    elements: Vec<Element>,
    /// The TRI4 points of every element, element by element.
    points: Vec<[f64; 2]>,
    /// The exact u and ∇u bound to `points` (see [`ErrorEvaluator::with_exact`]).
    bound: Option<ExactAt>,
    /// Per stabilised edge and Gauss point: weight · 2ρμ and the jump terms.
    jumps: Vec<(f64, Vec<(usize, f64)>)>,
    law: Elasticity,
}

impl ErrorEvaluator {
    pub fn new(mesh: &Mesh, space: &CrSpace, law: &Elasticity, rho: f64) -> Self {
        let elements: Vec<Element> = (0..mesh.tris.len()).map(|t| Element::new(mesh, t)).collect();
        let points = elements.iter().flat_map(|el| TRI4.map(|(l, _)| tri_point(el.pts, l))).collect();
        let pen = 2.0 * rho * law.mu;
        let mut jumps = Vec::new();
        for e in 0..mesh.edges.len() {
            if space.is_stabilised(mesh, e) {
                for (s, w) in GAUSS2 {
                    jumps.push((pen * w, jump_terms(mesh, e, s)));
                }
            }
        }
        ErrorEvaluator { elements, points, bound: None, jumps, law: *law }
    }

    /// Bind the exact solution to the quadrature points once: its parts that do not depend on t are then
    /// evaluated once for the run instead of at every time. [`ErrorEvaluator::errors`] must then be given
    /// the same `exact`.
    pub fn with_exact(mut self, exact: &Exact) -> Self {
        self.bound = Some(ExactAt::new(exact, self.points.clone()));
        self
    }

    /// Errors of the CR field with midpoint values `mid` against `exact` at time t.
    pub fn errors(&self, mesh: &Mesh, exact: &Exact, mid: &[[f64; 2]], t: f64) -> Result<ErrorNorms> {
        let (mut norms, failed) = self.errors_at(mesh, exact, &[(mid, t)]);
        match failed {
            Some(e) => Err(e),
            None => Ok(norms.remove(0)),
        }
    }

    /// Errors of several CR fields (midpoint values and time), with the exact solution evaluated chunk
    /// of elements by chunk of elements for all of them in turn: the spatial values bound to a chunk's
    /// points are read from memory once for all the fields instead of once for each. The same values
    /// as [`ErrorEvaluator::errors`] field by field. Returns the norms of the fields before the first
    /// one whose exact values are not finite, and that field's error.
    pub fn errors_at(
        &self,
        mesh: &Mesh,
        exact: &Exact,
        fields: &[(&[[f64; 2]], f64)],
    ) -> (Vec<ErrorNorms>, Option<Error>) {
        let owned;
        let bound = match &self.bound {
            Some(b) => b,
            None => {
                owned = ExactAt::new(exact, self.points.clone());
                &owned
            }
        };
        let nodes: Vec<_> = fields.iter().map(|&(_, t)| bound.node(t)).collect();
        let (per_element, nf) = (TRI4.len(), fields.len());
        // parts[k · nf + f]: the contributions of element k to field f
        let mut parts = vec![[0.0f64; 3]; self.elements.len() * nf];
        // the error of the first field (and within it the first chunk, in point order) that has a
        // non-finite exact value
        let failed: Mutex<Option<((usize, usize), Error)>> = Mutex::new(None);
        crate::parallel::for_chunks(&mut parts, CHUNK_ELEMENTS * nf.max(1), per_element * VALUES, |c, chunk| {
            let (first, n) = (c * CHUNK_ELEMENTS, chunk.len() / nf.max(1));
            let mut values = Vec::with_capacity(n * per_element * VALUES);
            for (f, (&(mid, _), node)) in fields.iter().zip(&nodes).enumerate() {
                if let Err(e) = bound.eval_range(node, first * per_element, n * per_element, &mut values) {
                    let mut slot = failed.lock().unwrap_or_else(|p| p.into_inner());
                    if slot.as_ref().is_none_or(|(at, _)| (f, c) < *at) {
                        *slot = Some(((f, c), e));
                    }
                    return;
                }
                for (k, v) in values.chunks_exact(per_element * VALUES).enumerate() {
                    chunk[k * nf + f] = self.element_errors(mesh, v, mid, first + k);
                }
            }
        });
        let failed = failed.into_inner().unwrap_or_else(|p| p.into_inner());
        let good = failed.as_ref().map_or(nf, |((f, _), _)| *f);
        let norms = (0..good)
            .map(|f| {
                let (mut en, mut h1, mut l2) = (0.0f64, 0.0f64, 0.0f64);
                for [e, h, l] in parts.iter().skip(f).step_by(nf) {
                    en += e;
                    h1 += h;
                    l2 += l;
                }
                en += self.jump_energy(fields[f].0);
                ErrorNorms { energy: en.max(0.0).sqrt(), h1: h1.sqrt(), l2: l2.sqrt() }
            })
            .collect();
        (norms, failed.map(|(_, e)| e))
    }

    /// (energy, H¹, L²) squared error contributions of element k, from the exact (u₀, u₁, ∂u/∂x...) at its
    /// quadrature points (`exact`, point-major).
    fn element_errors(&self, mesh: &Mesh, exact: &[f64], mid: &[[f64; 2]], k: usize) -> [f64; 3] {
        let el = &self.elements[k];
        let (mut en, mut h1, mut l2) = (0.0f64, 0.0f64, 0.0f64);
        let ue = mesh.tri_edges[k].map(|e| mid[e]);
        let gh = el.gradient(ue);
        for ((l, w), v) in TRI4.into_iter().zip(exact.chunks_exact(VALUES)) {
            let phi = Element::phi(l);
            let wt = w * el.area;
            let u = [v[0], v[1]];
            for c in 0..2 {
                let uh = phi[0] * ue[0][c] + phi[1] * ue[1][c] + phi[2] * ue[2][c];
                l2 += wt * (u[c] - uh) * (u[c] - uh);
            }
            let mut g = [[0.0; 2]; 2];
            for c in 0..2 {
                for d in 0..2 {
                    g[c][d] = v[2 + 2 * c + d] - gh[c][d];
                }
            }
            en += wt * self.law.energy_density(g);
            h1 += wt * (g[0][0] * g[0][0] + g[0][1] * g[0][1] + g[1][0] * g[1][0] + g[1][1] * g[1][1]);
        }
        [en, h1, l2]
    }

    /// The stabilisation part Σ_e (2ρμ/h_e) ∫_e |[u_h]|² of a CR field.
    pub fn jump_energy(&self, mid: &[[f64; 2]]) -> f64 {
        let mut en = 0.0;
        for (w, terms) in &self.jumps {
            let mut j = [0.0; 2];
            for &(e, p) in terms {
                j = [j[0] + p * mid[e][0], j[1] + p * mid[e][1]];
            }
            en += w * (j[0] * j[0] + j[1] * j[1]);
        }
        en
    }
}

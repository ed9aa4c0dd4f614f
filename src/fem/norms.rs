//! True errors against an exact solution u (with its exact gradient — never finite differences):
//!
//! * energy: |||u − u_h|||² = Σ_T ∫_T σ(u − u_h):ε(u − u_h) + Σ_{e ∈ interior ∪ Dirichlet} (2ρμ/h_e) ∫_e |[u_h]|²
//!   (the exact u is continuous and vanishes on Γ_D, so the jump of the error is the jump of u_h; with
//!   boundary data, `fem::lifting`, the jump of the error on a Dirichlet edge is u_h − u),
//! * broken H¹ seminorm |u − u_h|_{1,h} and L² norm ‖u − u_h‖,
//!
//! by the degree-4 triangle rule and the exact 2-point edge rule. The exact u and ∇u (six expressions,
//! bound to the quadrature points: separated in time or compiled, see [`super::exact`]) are evaluated
//! chunk of elements by chunk of elements, each chunk's values used at once while they are in the
//! processor's cache (not written out for the whole mesh and read back). Within a chunk the elements go
//! in batches of `LANES`, the element geometry stored by batch, so every sum is a loop over the
//! elements of a batch (vectorised) while each element's sum over its points keeps the order of an
//! element-by-element loop. Chunks run in parallel; the per-element contributions are summed in element
//! order, so the norms are bit-identical for any thread count.

use super::elasticity::Elasticity;
use super::exact::{ExactAt, VALUES};
use super::quadrature::{tri_point, GAUSS2, TRI4};
use super::space::{jump_terms, CrSpace, Element};
use crate::error::Error;
use crate::error::Result;
use crate::mesh::Mesh;
use crate::scene::expr::program::LANES;
use crate::scene::{Exact, Part, PartKind};
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

/// Rows of an element batch's geometry: the area, then ∇φ_i (i = 0, 1, 2; x then y).
const GEOMETRY: usize = 7;

/// The stabilisation's quadrature, flat: per stabilised edge and Gauss point q its weight · 2ρμ and
/// the terms of the jump, [u_h](x_q) = Σ coef · u_edge over `first[q]..first[q + 1]`.
struct Jumps {
    weight: Vec<f64>,
    first: Vec<usize>,
    edge: Vec<usize>,
    coef: Vec<f64>,
}

/// A batch of elements for [`ErrorEvaluator::batch_errors`]: batch b, its elements' edges, the exact
/// (u₀, u₁, ∂u₀/∂x, …) at their quadrature points (laid out as in `fem::exact`), the CR field's
/// midpoint values.
#[derive(Clone, Copy)]
struct Batch<'a> {
    b: usize,
    edges: &'a [[usize; 3]],
    exact: &'a [f64],
    mid: &'a [[f64; 2]],
}

/// Precomputed geometry for repeated error evaluation.
pub struct ErrorEvaluator {
    /// Triangles.
    n_elements: usize,
    /// By batch of [`LANES`] elements: [`GEOMETRY`] rows of LANES values (0 past the last element).
    geometry: Vec<f64>,
    /// The TRI4 points of every element, element by element (moved into `bound` once bound).
    points: Vec<[f64; 2]>,
    /// The exact u and ∇u bound to `points` (see [`ErrorEvaluator::with_exact`]).
    bound: Option<ExactAt>,
    /// Per stabilised edge and Gauss point: weight · 2ρμ and the jump terms.
    jumps: Jumps,
    /// With boundary data: the Gauss points on Γ_D (index into `jumps`, edge, point), where the exact u
    /// (or the data u_D, [`ErrorEvaluator::jump_energy_against`]) is subtracted from the jump; empty
    /// without data.
    boundary: Vec<(usize, usize, [f64; 2])>,
    law: Elasticity,
}

impl ErrorEvaluator {
    /// The evaluator on `mesh`; with boundary data (`has_data`) it keeps the Gauss points on Γ_D for
    /// [`ErrorEvaluator::jump_energy_against`].
    pub fn new(mesh: &Mesh, space: &CrSpace, has_data: bool, law: &Elasticity, rho: f64) -> Self {
        let n_elements = mesh.tris.len();
        let mut geometry = vec![0.0; n_elements.div_ceil(LANES) * GEOMETRY * LANES];
        let mut points = Vec::with_capacity(n_elements * TRI4.len());
        for t in 0..n_elements {
            let el = Element::new(mesh, t);
            points.extend(TRI4.map(|(l, _)| tri_point(el.pts, l)));
            let rows = &mut geometry[t / LANES * GEOMETRY * LANES..][..GEOMETRY * LANES];
            rows[t % LANES] = el.area;
            for i in 0..3 {
                for (d, g) in el.grad_phi(i).into_iter().enumerate() {
                    rows[(1 + 2 * i + d) * LANES + t % LANES] = g;
                }
            }
        }
        let pen = 2.0 * rho * law.mu;
        let mut jumps = Jumps { weight: Vec::new(), first: vec![0], edge: Vec::new(), coef: Vec::new() };
        let mut boundary = Vec::new();
        for e in 0..mesh.edges.len() {
            if space.is_stabilised(mesh, e) {
                for (s, w) in GAUSS2 {
                    if has_data && mesh.edge_tris[e].1.is_none() {
                        let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
                        boundary.push((jumps.weight.len(), e, super::quadrature::edge_point(a, b, s)));
                    }
                    jumps.weight.push(pen * w);
                    for (k, p) in jump_terms(mesh, e, s) {
                        jumps.edge.push(k);
                        jumps.coef.push(p);
                    }
                    jumps.first.push(jumps.edge.len());
                }
            }
        }
        ErrorEvaluator { n_elements, geometry, points, bound: None, jumps, boundary, law: *law }
    }

    /// Bind the exact solution to the quadrature points once: its parts that do not depend on t are then
    /// evaluated once for the run instead of at every time. [`ErrorEvaluator::errors`] must then be given
    /// the same `exact`.
    pub fn with_exact(mut self, exact: &Exact) -> Self {
        let points = match self.bound.take() {
            Some(b) => b.into_points(),
            None => std::mem::take(&mut self.points),
        };
        self.bound = Some(ExactAt::new(exact, points, TRI4.len()));
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
                owned = ExactAt::new(exact, self.points.clone(), TRI4.len());
                &owned
            }
        };
        let nodes: Vec<_> = fields.iter().map(|&(_, t)| bound.node(t)).collect();
        let nf = fields.len();
        // parts[k · nf + f]: the contributions of element k to field f
        let mut parts = vec![[0.0f64; 3]; self.n_elements * nf];
        // the error of the first field (and within it the first chunk, in point order) that has a
        // non-finite exact value
        let failed: Mutex<Option<((usize, usize), Error)>> = Mutex::new(None);
        crate::parallel::for_chunks(&mut parts, CHUNK_ELEMENTS * nf.max(1), TRI4.len() * VALUES, |c, chunk| {
            let n = chunk.len() / nf.max(1);
            let mut values = Vec::with_capacity(VALUES * TRI4.len() * LANES);
            let mut batch = [[0.0f64; 3]; LANES];
            for (f, (&(mid, _), node)) in fields.iter().zip(&nodes).enumerate() {
                for (j, first) in (0..n).step_by(LANES).enumerate() {
                    let (b, m) = (c * CHUNK_ELEMENTS / LANES + j, LANES.min(n - first));
                    if let Err(e) = bound.eval_batch(node, b, m, &mut values) {
                        let mut slot = failed.lock().unwrap_or_else(|p| p.into_inner());
                        if slot.as_ref().is_none_or(|(at, _)| (f, c) < *at) {
                            *slot = Some(((f, c), e));
                        }
                        return;
                    }
                    let edges = &mesh.tri_edges[b * LANES..b * LANES + m];
                    self.batch_errors(Batch { b, edges, exact: &values, mid }, &mut batch);
                    for (k, e) in batch[..m].iter().enumerate() {
                        chunk[(first + k) * nf + f] = *e;
                    }
                }
            }
        });
        let failed = failed.into_inner().unwrap_or_else(|p| p.into_inner());
        let good = failed.as_ref().map_or(nf, |((f, _), _)| *f);
        let mut failed = failed.map(|(_, e)| e);
        let mut norms = Vec::with_capacity(good);
        for (f, field) in fields.iter().enumerate().take(good) {
            let (mut en, mut h1, mut l2) = (0.0f64, 0.0f64, 0.0f64);
            for [e, h, l] in parts.iter().skip(f).step_by(nf) {
                en += e;
                h1 += h;
                l2 += l;
            }
            if self.boundary.is_empty() {
                en += self.jump_energy(field.0);
            } else {
                match self.boundary_values(exact, field.1) {
                    Ok(v) => en += self.jump_energy_minus(field.0, &v),
                    Err(e) => {
                        failed = Some(e);
                        break;
                    }
                }
            }
            norms.push(ErrorNorms { energy: en.max(0.0).sqrt(), h1: h1.sqrt(), l2: l2.sqrt() });
        }
        (norms, failed)
    }

    /// (energy, H¹, L²) squared error contributions of the elements of a batch into `out`: per element
    /// the sums over its points in order, as element by element.
    fn batch_errors(&self, batch: Batch, out: &mut [[f64; 3]; LANES]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2.
            return unsafe { self.batch_errors_avx2(batch, out) };
        }
        self.batch_errors_lanes(batch, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn batch_errors_avx2(&self, batch: Batch, out: &mut [[f64; 3]; LANES]) {
        self.batch_errors_lanes(batch, out)
    }

    /// [`ErrorEvaluator::batch_errors`] as loops over the lanes (elements), which the compiler vectorises
    /// (the same operations with or without AVX2: no fused multiply-add).
    #[inline(always)]
    fn batch_errors_lanes(&self, Batch { b, edges, exact, mid }: Batch, out: &mut [[f64; 3]; LANES]) {
        const L: usize = LANES;
        let pe = TRI4.len();
        let geo = &self.geometry[b * GEOMETRY * L..][..GEOMETRY * L];
        let row = |k: usize, q: usize| -> &[f64] { &exact[(k * pe + q) * L..][..L] };
        // the midpoint values u_i (component c) of the batch's elements
        let mut ue = [[[0.0f64; L]; 2]; 3];
        for (e, te) in edges.iter().enumerate() {
            for i in 0..3 {
                let m = mid[te[i]];
                ue[i][0][e] = m[0];
                ue[i][1][e] = m[1];
            }
        }
        // ∇u_h = Σ_i u_i ⊗ ∇φ_i, in Element::gradient's order
        let mut gh = [[[0.0f64; L]; 2]; 2];
        for (i, u) in ue.iter().enumerate() {
            for (c, uc) in u.iter().enumerate() {
                for (d, g) in gh[c].iter_mut().enumerate() {
                    let gp = &geo[(1 + 2 * i + d) * L..][..L];
                    for l in 0..L {
                        g[l] += uc[l] * gp[l];
                    }
                }
            }
        }
        let (mut en, mut h1, mut l2) = ([0.0f64; L], [0.0f64; L], [0.0f64; L]);
        for (q, (lq, w)) in TRI4.into_iter().enumerate() {
            let phi = Element::phi(lq);
            let (u0, u1) = (row(0, q), row(1, q));
            let (v00, v01, v10, v11) = (row(2, q), row(3, q), row(4, q), row(5, q));
            for l in 0..L {
                let wt = w * geo[l];
                for (c, u) in [u0[l], u1[l]].into_iter().enumerate() {
                    let uh = phi[0] * ue[0][c][l] + phi[1] * ue[1][c][l] + phi[2] * ue[2][c][l];
                    l2[l] += wt * (u - uh) * (u - uh);
                }
                let g = [[v00[l] - gh[0][0][l], v01[l] - gh[0][1][l]], [v10[l] - gh[1][0][l], v11[l] - gh[1][1][l]]];
                en[l] += wt * self.law.energy_density(g);
                h1[l] += wt * (g[0][0] * g[0][0] + g[0][1] * g[0][1] + g[1][0] * g[1][0] + g[1][1] * g[1][1]);
            }
        }
        for (l, o) in out.iter_mut().enumerate() {
            *o = [en[l], h1[l], l2[l]];
        }
    }

    /// The stabilisation part Σ_e (2ρμ/h_e) ∫_e |[u_h]|² of a CR field.
    pub fn jump_energy(&self, mid: &[[f64; 2]]) -> f64 {
        self.jump_energy_minus(mid, &[])
    }

    /// The exact u at the Γ_D points of `boundary` at time t.
    fn boundary_values(&self, exact: &Exact, t: f64) -> Result<Vec<(usize, [f64; 2])>> {
        self.boundary.iter().map(|&(q, _, x)| Ok((q, exact.u.eval(x[0], x[1], t)?))).collect()
    }

    /// The stabilisation part with the jump on Γ_D measured against data: Σ_{e interior} (2ρμ/h_e) ∫_e
    /// |[u_h]|² + Σ_{e ⊂ Γ_D} (2ρμ/h_e) ∫_e |u_h − u_D|², `u_d(e, x)` giving u_D at point x of Dirichlet
    /// edge e (the jump part of the true error, [`ErrorEvaluator::errors`], without the exact u). Without
    /// data, [`ErrorEvaluator::jump_energy`].
    pub fn jump_energy_against(
        &self,
        mid: &[[f64; 2]],
        u_d: impl Fn(usize, [f64; 2]) -> Result<[f64; 2]>,
    ) -> Result<f64> {
        let sub: Vec<(usize, [f64; 2])> =
            self.boundary.iter().map(|&(q, e, x)| Ok((q, u_d(e, x)?))).collect::<Result<_>>()?;
        Ok(self.jump_energy_minus(mid, &sub))
    }

    /// The stabilisation part of the displacement `mid` (unknowns plus lifting) at time t of a scene with
    /// boundary parts `parts`: with boundary data (`has_data`), [`ErrorEvaluator::jump_energy_against`] its
    /// Dirichlet parts' u_D(t); without, [`ErrorEvaluator::jump_energy`].
    pub fn jump_energy_at(
        &self,
        mid: &[[f64; 2]],
        space: &CrSpace,
        has_data: bool,
        parts: &[Part],
        t: f64,
    ) -> Result<f64> {
        if !has_data {
            return Ok(self.jump_energy(mid));
        }
        self.jump_energy_against(mid, |e, x| match space.edge_part[e].map(|k| &parts[k].kind) {
            Some(PartKind::Dirichlet(Some(u))) => u.eval(x[0], x[1], t),
            _ => Ok([0.0; 2]),
        })
    }

    /// [`ErrorEvaluator::jump_energy`] with `sub` (jump point, value; increasing points) subtracted
    /// from the jump at those points.
    fn jump_energy_minus(&self, mid: &[[f64; 2]], sub: &[(usize, [f64; 2])]) -> f64 {
        let (mut en, jp) = (0.0, &self.jumps);
        let mut sub = sub.iter().peekable();
        for (q, (w, at)) in jp.weight.iter().zip(jp.first.windows(2)).enumerate() {
            let mut j = [0.0; 2];
            for (&e, &p) in jp.edge[at[0]..at[1]].iter().zip(&jp.coef[at[0]..at[1]]) {
                j = [j[0] + p * mid[e][0], j[1] + p * mid[e][1]];
            }
            if let Some((_, u)) = sub.next_if(|(k, _)| *k == q) {
                j = [j[0] - u[0], j[1] - u[1]];
            }
            en += w * (j[0] * j[0] + j[1] * j[1]);
        }
        en
    }
}

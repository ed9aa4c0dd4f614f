//! Assembly of the stabilised CR stiffness K and of the load vector lⁿ on the unknowns of V_h.
//!
//! K_ij = a_h(ψ_j, ψ_i) with
//!   a_h(v, w) = Σ_T |T| (λ div v div w + 2μ ε(v):ε(w)) + Σ_{e ∈ interior ∪ Dirichlet} (2ρμ/h_e) ∫_e [v]·[w],
//! the jump [v] = v|T1 − v|T2 (v on a Dirichlet edge) integrated by 2-point Gauss — exact, whereas a
//! midpoint rule would see nothing because the jump of two CR functions has zero mean on each edge.
//! Loads (lⁿ, v) = ∫ f(tₙ)·v (Dunavant degree 4) + Σ_{Neumann e} ∫_e g(tₙ)·v (3-point Gauss). K is built
//! once from triplets; the load operator stores quadrature points and basis values once, so each step
//! only evaluates the expressions.

use crate::cr::{CrSpace, EdgeDof, Element};
use crate::error::Result;
use crate::expr::Vec2Expr;
use crate::mesh::Mesh;
use crate::quadrature::{edge_point, tri_point, GAUSS2, GAUSS3, TRI4};
use crate::scene::{Material, PartKind, Scene};
use faer::sparse::{SparseColMat, SymbolicSparseColMat};

/// Add the coupling block between the midpoint values of edges a and b to the triplets:
/// K[k, l] += Σ_cd v_k[c] block[c][d] w_l[d] over the terms of both edges.
fn scatter(space: &CrSpace, a: usize, b: usize, block: [[f64; 2]; 2], trip: &mut Vec<(usize, usize, f64)>) {
    for (k, v) in space.edge_dof[a].terms() {
        for (l, w) in space.edge_dof[b].terms() {
            let val =
                v[0] * (block[0][0] * w[0] + block[0][1] * w[1]) + v[1] * (block[1][0] * w[0] + block[1][1] * w[1]);
            if val != 0.0 {
                trip.push((k, l, val));
            }
        }
    }
}

/// Element stiffness block between local basis functions i and j: [c][d] = ∫_T σ(φ_j e_d):ε(φ_i e_c).
pub fn element_block(el: &Element, mat: &Material, i: usize, j: usize) -> [[f64; 2]; 2] {
    let (lam, mu) = (mat.lambda(), mat.mu());
    let (gi, gj) = (el.grad_phi(i), el.grad_phi(j));
    let dot = gi[0] * gj[0] + gi[1] * gj[1];
    let mut b = [[0.0; 2]; 2];
    for c in 0..2 {
        for d in 0..2 {
            let delta = if c == d { dot } else { 0.0 };
            b[c][d] = el.area * (lam * gi[c] * gj[d] + mu * (delta + gi[d] * gj[c]));
        }
    }
    b
}

/// The jump of the CR basis across edge e at parameter s: (edge, signed basis value) for both sides.
pub fn jump_terms(mesh: &Mesh, e: usize, s: f64) -> Vec<(usize, f64)> {
    let [a, b] = mesh.edges[e].map(|v| mesh.points[v]);
    let x = edge_point(a, b, s);
    let (t1, t2) = mesh.edge_tris[e];
    let mut out = Vec::with_capacity(6);
    for (t, sign) in [(Some(t1), 1.0), (t2, -1.0)] {
        if let Some(t) = t {
            let el = Element::new(mesh, t);
            let phi = Element::phi(el.bary(x));
            for i in 0..3 {
                out.push((mesh.tri_edges[t][i], sign * phi[i]));
            }
        }
    }
    out
}

/// True if edge e carries the stabilisation (interior or Dirichlet).
pub fn is_stabilised(mesh: &Mesh, space: &CrSpace, e: usize) -> bool {
    mesh.edge_tris[e].1.is_some() || space.edge_dof[e] == EdgeDof::Fixed
}

/// Assemble K (both triangles of the symmetric matrix stored).
pub fn stiffness(mesh: &Mesh, space: &CrSpace, mat: &Material, rho: f64) -> Result<SparseColMat<usize, f64>> {
    let mut trip = Vec::with_capacity(36 * mesh.tris.len() + 100 * mesh.edges.len());
    for t in 0..mesh.tris.len() {
        let el = Element::new(mesh, t);
        for i in 0..3 {
            for j in 0..3 {
                scatter(space, mesh.tri_edges[t][i], mesh.tri_edges[t][j], element_block(&el, mat, i, j), &mut trip);
            }
        }
    }
    let pen = 2.0 * rho * mat.mu();
    for e in 0..mesh.edges.len() {
        if !is_stabilised(mesh, space, e) {
            continue;
        }
        // (2ρμ/h_e) ∫_e [v]·[w] = 2ρμ Σ_q w_q [v](x_q)·[w](x_q)  (the weights sum to 1, ∫_e = h_e Σ_q w_q),
        // summed into the local matrix M_ab of the ≤ 6 basis functions of the two triangles first (the
        // shared edge's function appears on both sides and is merged) and scattered once.
        let mut idx: Vec<usize> = Vec::with_capacity(6);
        let mut m = [[0.0f64; 6]; 6];
        for (s, w) in GAUSS2 {
            let mut p = [0.0f64; 6];
            for (a, pa) in jump_terms(mesh, e, s) {
                let i = idx.iter().position(|&x| x == a).unwrap_or_else(|| {
                    idx.push(a);
                    idx.len() - 1
                });
                p[i] += pa;
            }
            for i in 0..idx.len() {
                for j in 0..idx.len() {
                    m[i][j] += pen * w * p[i] * p[j];
                }
            }
        }
        for (i, &a) in idx.iter().enumerate() {
            for (j, &b) in idx.iter().enumerate() {
                scatter(space, a, b, [[m[i][j], 0.0], [0.0, m[i][j]]], &mut trip);
            }
        }
    }
    Ok(csc_from_triplets(space.n_dofs, &trip))
}

/// Square CSC matrix from (row, col, value) triplets, duplicates summed: a counting sort by column,
/// then a sort of each (short) column by row. O(nnz · log(column length)).
pub fn csc_from_triplets(n: usize, trip: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let mut start = vec![0usize; n + 1];
    for &(_, c, _) in trip {
        start[c + 1] += 1;
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    let mut slot = start.clone();
    let mut entries = vec![(0usize, 0.0f64); trip.len()];
    for &(r, c, v) in trip {
        entries[slot[c]] = (r, v);
        slot[c] += 1;
    }
    let (mut col_ptr, mut row_idx, mut val) =
        (Vec::with_capacity(n + 1), Vec::with_capacity(trip.len() / 2), Vec::with_capacity(trip.len() / 2));
    col_ptr.push(0);
    for j in 0..n {
        let col = &mut entries[start[j]..start[j + 1]];
        col.sort_unstable_by_key(|e| e.0);
        for &(r, v) in col.iter() {
            if row_idx.len() > col_ptr[j] && *row_idx.last().expect("nonempty column") == r {
                *val.last_mut().expect("nonempty column") += v;
            } else {
                row_idx.push(r);
                val.push(v);
            }
        }
        col_ptr.push(row_idx.len());
    }
    SparseColMat::new(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx), val)
}

/// y = K x for a CSC matrix.
pub fn matvec(k: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    let s = k.symbolic();
    let (cp, ri, val) = (s.col_ptr(), s.row_idx(), k.val());
    for j in 0..s.ncols() {
        let xj = x[j];
        for p in cp[j]..cp[j + 1] {
            y[ri[p]] += val[p] * xj;
        }
    }
}

/// A quadrature point of a load term: position, and the (edge, weight · φ) pairs it feeds.
#[derive(Clone, Debug)]
struct LoadPoint {
    x: [f64; 2],
    edges: [(usize, f64); 3],
}

/// Precomputed quadrature for one vector load (body force or one Neumann part).
#[derive(Clone, Debug)]
struct LoadTerm {
    expr: Vec2Expr,
    points: Vec<LoadPoint>,
}

/// The load functional t ↦ l(t) on the unknowns.
#[derive(Clone, Debug)]
pub struct Loads {
    terms: Vec<LoadTerm>,
    n_dofs: usize,
    /// The unknowns any load can touch, increasing (all of them with a body force, only boundary ones
    /// with tractions alone); `slot[k]` is the position of unknown k in it.
    support: Vec<usize>,
    slot: Vec<usize>,
}

impl Loads {
    /// Quadrature points of the body force (if any) and of every Neumann part with a traction.
    pub fn new(scene: &Scene, mesh: &Mesh, space: &CrSpace) -> Loads {
        let mut terms = Vec::new();
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
            terms.push(LoadTerm { expr: f.clone(), points });
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
            terms.push(LoadTerm { expr: g.clone(), points });
        }
        let mut touched = vec![false; space.n_dofs];
        for p in terms.iter().flat_map(|t| &t.points) {
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
        Loads { terms, n_dofs: space.n_dofs, support, slot }
    }

    /// True if some load depends on t.
    pub fn depends_on_t(&self) -> bool {
        self.terms.iter().any(|t| t.expr.depends_on_t())
    }

    /// The unknowns a load can be nonzero on (increasing).
    pub fn support(&self) -> &[usize] {
        &self.support
    }

    /// l(t) restricted to [`Loads::support`], into `out`.
    pub fn assemble_on_support(&self, space: &CrSpace, t: f64, out: &mut Vec<f64>) -> Result<()> {
        out.clear();
        out.resize(self.support.len(), 0.0);
        for term in &self.terms {
            // the expression values in parallel (order kept), the sums sequentially: bit-identical results
            let values = crate::parallel::map(&term.points, |p| term.expr.eval(p.x[0], p.x[1], t));
            for (p, v) in term.points.iter().zip(values) {
                let v = v?;
                for &(e, wphi) in &p.edges {
                    for (k, c) in space.edge_dof[e].terms() {
                        out[self.slot[k]] += wphi * (c[0] * v[0] + c[1] * v[1]);
                    }
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
    pub fn assemble(&self, space: &CrSpace, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let mut s = Vec::new();
        self.assemble_on_support(space, t, &mut s)?;
        self.expand(&s, out);
        Ok(())
    }
}

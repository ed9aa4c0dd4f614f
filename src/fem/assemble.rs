//! Assembly of the stabilised CR stiffness K on the unknowns of V_h, once per run.
//!
//! K_ij = a_h(ψ_j, ψ_i) with
//!   a_h(v, w) = Σ_T ∫_T σ(v):ε(w) + Σ_{e ∈ interior ∪ Dirichlet} (2ρμ/h_e) ∫_e [v]·[w],
//! the volume term from the one law ([`Elasticity::element_block`]), the jump [v] = v|T1 − v|T2 (v on a
//! Dirichlet edge) integrated by 2-point Gauss — exact, whereas a midpoint rule would see nothing
//! because the jump of two CR functions has zero mean on each edge.
//!
//! Assembled straight into compressed columns, without triplets: the midpoint values of edges a and b
//! are coupled exactly when a and b lie in one triangle or in two triangles sharing an edge (the jump
//! on that edge), so the pattern is known from the mesh ([`EdgePattern`]): each edge gets its sorted
//! list of coupled edges (a block row of ≤ 13 edges), mapped to the unknowns (two per free edge, the
//! tangential one on Γ_C, none on Γ_D), whose numbering follows the edges, so every column comes out
//! sorted. Entries that are zero for every mesh (the x–y coupling of two edges that meet only through
//! a jump term) are stored too, so the pattern is known before the values: the symbolic factorisation
//! is computed from it (from the graph of the edges, its block form) while the values are assembled, in
//! the lower triangle alone in a run ([`Triangles`]). The 2 × 2 blocks of the midpoint values (volume
//! terms triangle by triangle, then jump terms edge by edge) are added straight into K's values, those
//! of a tangential Γ_C edge projected once summed. Cost O(edges); the former triplet route (4M triplets
//! sorted by column at 24,640 unknowns) took 40 % of Example 5.1's set-up.

use super::elasticity::Elasticity;
use super::quadrature::GAUSS2;
use super::space::{jump_terms_with, CrSpace, EdgeDof, Element};
use crate::mesh::Mesh;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, SymbolicSparseColMatRef};
use std::collections::HashMap;

/// The edges coupled to each edge (itself included), sorted: the block pattern of K as compressed rows
/// (`ptr`, `idx`). Known from the mesh alone, so the fill-reducing ordering can be computed from it
/// while K's values are assembled.
pub struct EdgePattern {
    ptr: Vec<usize>,
    idx: Vec<usize>,
}

/// From this many edges [`EdgePattern::new`] makes the two halves of its rows on rayon's threads (with
/// one thread in force, one after the other): everything else of the set-up's phase 1 waits for it (at
/// refine 8 of Example 5.1, 0.8 M edges, 0.18 s of one core). Below, about 10 ms of work, handing it
/// to the pool (tens of µs) and copying the second half save too little to matter.
const SPLIT_MIN_EDGES: usize = 50_000;

impl EdgePattern {
    pub fn new(mesh: &Mesh) -> EdgePattern {
        let ne = mesh.edges.len();
        if ne < SPLIT_MIN_EDGES {
            return EdgePattern::rows(mesh, 0..ne);
        }
        let (mut first, second) =
            rayon::join(|| EdgePattern::rows(mesh, 0..ne / 2), || EdgePattern::rows(mesh, ne / 2..ne));
        let base = first.idx.len();
        first.ptr.extend(second.ptr[1..].iter().map(|&p| p + base));
        first.idx.extend_from_slice(&second.idx);
        first
    }

    /// The rows of the edges `edges` alone (their pointers from 0).
    fn rows(mesh: &Mesh, edges: std::ops::Range<usize>) -> EdgePattern {
        let ne = edges.len();
        let (mut ptr, mut idx) = (Vec::with_capacity(ne + 1), Vec::with_capacity(14 * ne));
        ptr.push(0);
        let mut near: Vec<usize> = Vec::with_capacity(32);
        for e in edges {
            near.clear();
            let (t1, t2) = mesh.edge_tris[e];
            for t in std::iter::once(t1).chain(t2) {
                // the edges of t and of its neighbours across its edges
                for &f in &mesh.tri_edges[t] {
                    let (s1, s2) = mesh.edge_tris[f];
                    for u in std::iter::once(s1).chain(s2) {
                        near.extend_from_slice(&mesh.tri_edges[u]);
                    }
                }
            }
            near.sort_unstable();
            near.dedup();
            idx.extend_from_slice(&near);
            ptr.push(idx.len());
        }
        EdgePattern { ptr, idx }
    }

    /// The graph of K's unknowns with the unknowns of an edge as one vertex, as (`first`, `start`,
    /// `adj`) for `solve::cholesky::Graph`: vertex g = the g-th edge with unknowns, holding the unknowns
    /// `first[g]..first[g + 1]`, adjacent to the coupled edges with unknowns (sorted, no self loop).
    /// Equal to the graph read from K as long as no 2 × 2 block of two coupled edges vanishes entirely
    /// (on each side e of their triangles, two CR basis functions whose traces are ±(1, −1) have
    /// ∫_e φ_a φ_b = ∓h_e/3 ≠ 0), so the ordering, hence every result, is the same either way
    /// (tests/library/elasticity.rs checks the equality).
    pub fn unknown_graph(&self, space: &CrSpace) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
        let first = space.unknown_groups();
        let mut vertex = vec![usize::MAX; space.edge_dof.len()];
        let mut g = 0;
        for (e, d) in space.edge_dof.iter().enumerate() {
            if d.terms().next().is_some() {
                vertex[e] = g;
                g += 1;
            }
        }
        let (mut start, mut adj) = (Vec::with_capacity(g + 1), Vec::with_capacity(self.idx.len()));
        start.push(0);
        for e in 0..space.edge_dof.len() {
            if vertex[e] == usize::MAX {
                continue;
            }
            adj.extend(
                self.idx[self.ptr[e]..self.ptr[e + 1]]
                    .iter()
                    .map(|&b| vertex[b])
                    .filter(|&v| v != usize::MAX && v != vertex[e]),
            );
            start.push(adj.len());
        }
        (first, start, adj)
    }

    /// The points of the vertices of [`EdgePattern::unknown_graph`]: the midpoints of the edges with
    /// unknowns, in the same order (for the ordering by coordinate bisection, `solve::cholesky`'s coordinate bisection).
    pub fn unknown_points(mesh: &Mesh, space: &CrSpace) -> Vec<[f64; 2]> {
        let with_unknowns = |e: &usize| space.edge_dof[*e].terms().next().is_some();
        (0..space.edge_dof.len()).filter(with_unknowns).map(|e| mesh.midpoint(e)).collect()
    }
}

/// K's values, summed in place in the mesh's pattern ([`EdgePattern::unknown_pattern`]).
///
/// `add(a, b, m)` adds the 2 × 2 block m of midpoint values (columns: edge a's components, rows: edge
/// b's) to K[unknown of b, unknown of a]. Between two free edges (unknowns along the axes) that is one
/// entry per component pair, added straight into K. A block with a tangential Γ_C edge (an unknown along
/// τ) is summed as a block and projected once at the end, K[k, l] = w_lᵀ block v_k, so every entry is the
/// same sum as with all blocks summed first.
struct Values<'a> {
    pattern: &'a EdgePattern,
    space: &'a CrSpace,
    col_ptr: &'a [usize],
    stored: Triangles,
    /// The unknowns of each edge.
    count: Vec<usize>,
    /// Where block p's rows start within a column of its edge: with both triangles stored, the same in
    /// both columns; with the lower one, after the edge's own rows, for a block below the diagonal.
    off: Vec<usize>,
    val: Vec<f64>,
    /// Blocks of a tangential edge: position p → (column edge, sum).
    projected: HashMap<usize, (usize, [[f64; 2]; 2])>,
}

impl Values<'_> {
    fn add(&mut self, a: usize, b: usize, m: [[f64; 2]; 2]) {
        let (da, db) = (self.space.edge_dof[a], self.space.edge_dof[b]);
        if matches!(da, EdgeDof::Fixed) || matches!(db, EdgeDof::Fixed) {
            return;
        }
        let (ptr, idx) = (&self.pattern.ptr, &self.pattern.idx);
        let p = ptr[a]
            + idx[ptr[a]..ptr[a + 1]].iter().position(|&x| x == b).expect("edges of one patch are in the pattern");
        match da {
            EdgeDof::Free(cols) if matches!(db, EdgeDof::Free(_)) => {
                for (c, &col) in cols.iter().enumerate() {
                    if let Some((at, from)) = self.rows_at(p, a, col, c) {
                        self.val[at..at + 2 - from].iter_mut().zip(&m[c][from..]).for_each(|(v, x)| *v += x);
                    }
                }
            }
            _ => {
                let blk = &mut self.projected.entry(p).or_insert((a, [[0.0; 2]; 2])).1;
                for c in 0..2 {
                    for d in 0..2 {
                        blk[c][d] += m[c][d];
                    }
                }
            }
        }
    }

    /// Where the rows of block p (edge b = `idx[p]` in edge a's row) are stored in column `col`, edge a's
    /// c-th unknown: (position, the first of b's unknowns stored there), `None` if none is (the block
    /// above the diagonal when only the lower triangle is stored). Edges' unknowns are numbered in the
    /// edges' order, so b's rows lie below a's column when b > a.
    fn rows_at(&self, p: usize, a: usize, col: usize, c: usize) -> Option<(usize, usize)> {
        use std::cmp::Ordering::{Equal, Greater, Less};
        match (self.stored, self.pattern.idx[p].cmp(&a)) {
            (Triangles::Both, _) => Some((self.col_ptr[col] + self.off[p], 0)),
            (Triangles::Lower, Less) => None,
            (Triangles::Lower, Equal) => Some((self.col_ptr[col], c)),
            (Triangles::Lower, Greater) => Some((self.col_ptr[col] + self.count[a] - c + self.off[p], 0)),
        }
    }

    /// The entries of the projected blocks.
    fn finish(mut self) -> Vec<f64> {
        for (&p, &(a, blk)) in &self.projected {
            let b = self.pattern.idx[p];
            for (c, (l, w)) in self.space.edge_dof[a].terms().enumerate() {
                let Some((at, from)) = self.rows_at(p, a, l, c) else { continue };
                for (i, (_, v)) in self.space.edge_dof[b].terms().enumerate().skip(from) {
                    self.val[at + i - from] =
                        v[0] * (blk[0][0] * w[0] + blk[1][0] * w[1]) + v[1] * (blk[0][1] * w[0] + blk[1][1] * w[1]);
                }
            }
        }
        self.val
    }
}

/// Which triangles of the symmetric K are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Triangles {
    /// Both: [`EdgePattern::unknown_pattern`].
    Both,
    /// The lower one (rows ≥ columns), the one a run keeps: [`EdgePattern::unknown_pattern_lower`].
    Lower,
}

/// Assemble K (both triangles of the symmetric matrix stored).
pub fn stiffness(mesh: &Mesh, space: &CrSpace, law: &Elasticity, rho: f64) -> SparseColMat<usize, f64> {
    let pattern = EdgePattern::new(mesh);
    let k = pattern.unknown_pattern(space);
    let val = stiffness_values(&pattern, (k.as_ref(), Triangles::Both), mesh, space, law, rho);
    SparseColMat::new(k, val)
}

/// K's values in its pattern `k_pattern` of the triangles `stored` (of `pattern`: the lower triangle alone
/// or both), made beforehand. Every stored entry is the same sum, in the same order, either way.
pub fn stiffness_values(
    pattern: &EdgePattern,
    (k_pattern, stored): (SymbolicSparseColMatRef<'_, usize>, Triangles),
    mesh: &Mesh,
    space: &CrSpace,
    law: &Elasticity,
    rho: f64,
) -> Vec<f64> {
    let count: Vec<usize> = space.edge_dof.iter().map(|d| d.terms().count()).collect();
    let mut off = vec![0usize; pattern.idx.len()];
    for a in 0..count.len() {
        let mut at = 0;
        for p in pattern.ptr[a]..pattern.ptr[a + 1] {
            off[p] = at;
            // with the lower triangle, only the blocks below the diagonal are offset
            if stored == Triangles::Both || pattern.idx[p] > a {
                at += count[pattern.idx[p]];
            }
        }
    }
    let mut k = Values {
        pattern,
        space,
        col_ptr: k_pattern.col_ptr(),
        stored,
        count,
        off,
        val: crate::machine::written_zeros(k_pattern.compute_nnz()),
        projected: HashMap::new(),
    };
    let elements: Vec<Element> = (0..mesh.tris.len()).map(|t| Element::new(mesh, t)).collect();
    for (t, el) in elements.iter().enumerate() {
        for i in 0..3 {
            for j in 0..3 {
                k.add(
                    mesh.tri_edges[t][i],
                    mesh.tri_edges[t][j],
                    law.element_block(el.area, el.grad_phi(i), el.grad_phi(j)),
                );
            }
        }
    }
    let pen = 2.0 * rho * law.mu;
    for e in 0..mesh.edges.len() {
        if !space.is_stabilised(mesh, e) {
            continue;
        }
        // (2ρμ/h_e) ∫_e [v]·[w] = 2ρμ Σ_q w_q [v](x_q)·[w](x_q)  (the weights sum to 1, ∫_e = h_e Σ_q w_q),
        // summed into the local matrix M_ab of the ≤ 6 basis functions of the two triangles first (the
        // shared edge's function appears on both sides and is merged) and added once.
        let mut idx = [0usize; 6];
        let mut len = 0;
        let mut m = [[0.0f64; 6]; 6];
        for (s, w) in GAUSS2 {
            let mut p = [0.0f64; 6];
            let (terms, n_terms) = jump_terms_with(mesh, e, s, |t| elements[t]);
            for &(a, pa) in &terms[..n_terms] {
                let i = idx[..len].iter().position(|&x| x == a).unwrap_or_else(|| {
                    idx[len] = a;
                    len += 1;
                    len - 1
                });
                p[i] += pa;
            }
            for i in 0..len {
                for j in 0..len {
                    m[i][j] += pen * w * p[i] * p[j];
                }
            }
        }
        for i in 0..len {
            for j in 0..len {
                k.add(idx[i], idx[j], [[m[i][j], 0.0], [0.0, m[i][j]]]);
            }
        }
    }
    k.finish()
}

impl EdgePattern {
    /// The pattern of K on the unknowns: K[k, l] for every unknown k of an edge a and l of an edge b
    /// coupled to a, known before K's values (the symbolic factorisation is computed from its block form,
    /// the graph of the edges, beside the assembly). Entries that are zero for every mesh are stored too (the x–y coupling of two
    /// edges that meet only through a jump term): with them K's pattern is this one whatever its
    /// values. Symmetric, every column sorted (block row b read as a column gives the column's rows in
    /// increasing order, since the unknowns are numbered edge by edge).
    pub fn unknown_pattern(&self, space: &CrSpace) -> SymbolicSparseColMat<usize> {
        self.pattern_of(space, false)
    }

    /// The lower triangle (rows ≥ columns) of [`EdgePattern::unknown_pattern`], made directly: the
    /// pattern a run keeps K in and gives to the symbolic factorisation (`stepping::setup`).
    pub fn unknown_pattern_lower(&self, space: &CrSpace) -> SymbolicSparseColMat<usize> {
        self.pattern_of(space, true)
    }

    fn pattern_of(&self, space: &CrSpace, lower: bool) -> SymbolicSparseColMat<usize> {
        let n = space.n_dofs;
        let (ptr, idx) = (&self.ptr, &self.idx);
        let count: Vec<usize> = space.edge_dof.iter().map(|d| d.terms().count()).collect();
        let nnz = (0..count.len()).map(|b| count[b] * idx[ptr[b]..ptr[b + 1]].iter().map(|&a| count[a]).sum::<usize>());
        let nnz = nnz.sum::<usize>();
        let mut row_idx = Vec::with_capacity(if lower { (nnz + n) / 2 } else { nnz });
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        for (b, dof_b) in space.edge_dof.iter().enumerate() {
            for (l, _) in dof_b.terms() {
                for &a in &idx[ptr[b]..ptr[b + 1]] {
                    row_idx.extend(space.edge_dof[a].terms().map(|(k, _)| k).filter(|&k| !lower || k >= l));
                }
                col_ptr.push(row_idx.len());
            }
        }
        SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx)
    }
}

#[cfg(test)]
mod tests {
    use super::{EdgePattern, SPLIT_MIN_EDGES};
    use crate::mesh::{Diagonal, Mesh, MeshSpec};

    /// The system shall make the same pattern of coupled edges in two halves (on a mesh of
    /// [`SPLIT_MIN_EDGES`] edges or more) as in one piece.
    #[test]
    fn the_pattern_in_two_halves_is_the_pattern_in_one() {
        let corners = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]];
        let spec = MeshSpec::Structured { corners, cells: [130, 130], diagonal: Diagonal::First, refine: 0 };
        let mesh = Mesh::from_spec(&spec).unwrap();
        assert!(mesh.edges.len() >= SPLIT_MIN_EDGES, "{} edges: the split is not exercised", mesh.edges.len());
        let (split, whole) = (EdgePattern::new(&mesh), EdgePattern::rows(&mesh, 0..mesh.edges.len()));
        assert_eq!((split.ptr, split.idx), (whole.ptr, whole.idx));
    }
}

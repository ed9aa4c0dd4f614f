//! Prolongation of a CR field from a coarse mesh to a finer mesh covering the same domain:
//! P u_c = I_CR^fine(u_c), the fine edge means of the coarse broken-P1 function. On a fine edge inside a
//! coarse triangle that is the coarse function at the edge midpoint; on a fine edge lying on a coarse
//! edge, where u_c jumps, the mean of both sides is taken. Used for the paper's consecutive-mesh error
//! |||u_fine − P u_coarse||| and for errors against a finer reference solution.
//!
//! Coarse triangles are found by a bucket grid over their bounding boxes (fine triangle centroids lie
//! strictly inside one coarse triangle when the meshes are nested).

use super::space::{CrSpace, Element};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Point location in a triangle mesh.
struct Locator {
    lo: [f64; 2],
    cell: [f64; 2],
    dims: [usize; 2],
    buckets: Vec<Vec<usize>>,
    elements: Vec<Element>,
}

impl Locator {
    fn new(mesh: &Mesh) -> Locator {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &mesh.points {
            for d in 0..2 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        let side = (mesh.tris.len() as f64).sqrt().ceil().max(1.0) as usize;
        let dims = [side, side];
        let cell = [(hi[0] - lo[0]) / side as f64 * (1.0 + 1e-12), (hi[1] - lo[1]) / side as f64 * (1.0 + 1e-12)];
        let mut buckets = vec![Vec::new(); side * side];
        let elements: Vec<Element> = (0..mesh.tris.len()).map(|t| Element::new(mesh, t)).collect();
        for (t, el) in elements.iter().enumerate() {
            let (mut a, mut b) = ([usize::MAX; 2], [0usize; 2]);
            for p in &el.pts {
                for d in 0..2 {
                    let k = (((p[d] - lo[d]) / cell[d]).floor().max(0.0) as usize).min(dims[d] - 1);
                    a[d] = a[d].min(k);
                    b[d] = b[d].max(k);
                }
            }
            for i in a[0]..=b[0] {
                for j in a[1]..=b[1] {
                    buckets[j * dims[0] + i].push(t);
                }
            }
        }
        Locator { lo, cell, dims, buckets, elements }
    }

    /// Triangle containing x (the one with the largest minimal barycentric coordinate nearby).
    fn find(&self, x: [f64; 2]) -> Option<(usize, [f64; 3])> {
        let k = |d: usize| (((x[d] - self.lo[d]) / self.cell[d]).floor().max(0.0) as usize).min(self.dims[d] - 1);
        let mut best: Option<(usize, [f64; 3])> = None;
        for &t in &self.buckets[k(1) * self.dims[0] + k(0)] {
            let l = self.elements[t].bary(x);
            let m = l[0].min(l[1]).min(l[2]);
            if best.is_none_or(|(_, bl)| m > bl[0].min(bl[1]).min(bl[2])) {
                best = Some((t, l));
            }
        }
        best.filter(|(_, l)| l[0].min(l[1]).min(l[2]) > -1e-9)
    }
}

/// For every fine triangle, the coarse triangle containing its centroid (nested meshes).
pub fn parent_triangles(coarse: &Mesh, fine: &Mesh) -> Result<Vec<usize>> {
    let loc = Locator::new(coarse);
    (0..fine.tris.len())
        .map(|t| {
            let [a, b, c] = fine.tris[t].map(|v| fine.points[v]);
            let centroid = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
            loc.find(centroid).map(|(ct, _)| ct).ok_or_else(|| {
                Error::mesh(
                    &fine.source,
                    format!("fine triangle at ({:.6}, {:.6}) lies outside the coarse mesh", centroid[0], centroid[1]),
                )
            })
        })
        .collect()
}

/// P u_c on the fine space, from the coarse unknowns `u_c`.
pub fn prolong(coarse: (&Mesh, &CrSpace), u_c: &[f64], fine: (&Mesh, &CrSpace)) -> Result<Vec<f64>> {
    let parent = parent_triangles(coarse.0, fine.0)?;
    Ok(prolong_with(&parent, coarse, u_c, fine))
}

/// [`prolong`] with the coarse parent of every fine triangle ([`parent_triangles`]) computed once.
pub fn prolong_with(parent: &[usize], coarse: (&Mesh, &CrSpace), u_c: &[f64], fine: (&Mesh, &CrSpace)) -> Vec<f64> {
    Prolongation::new(parent, coarse.0, fine).apply(coarse.1, u_c, fine.1)
}

/// P as an operator, for prolonging many fields between the same two meshes: for every fine edge, the values φ_i(m) of the CR basis functions of its (one or two) fine triangles' coarse
/// parents at its midpoint m, with their coarse edges. Each field then costs a gather; the values are
/// the same, bit for bit, as computing the geometry anew for it.
pub struct Prolongation {
    /// Fine edge e's terms are `terms[start[e]..start[e + 1]]`, three per parent triangle.
    start: Vec<usize>,
    /// (coarse edge, φ value).
    terms: Vec<(usize, f64)>,
}

impl Prolongation {
    /// The operator from the coarse mesh to the fine space (`parent`: [`parent_triangles`]).
    pub fn new(parent: &[usize], coarse: &Mesh, fine: (&Mesh, &CrSpace)) -> Prolongation {
        let (fm, fs) = fine;
        let mut start = Vec::with_capacity(fs.edge_dof.len() + 1);
        let mut terms = Vec::with_capacity(6 * fs.edge_dof.len());
        start.push(0);
        for e in 0..fs.edge_dof.len() {
            let m = fm.midpoint(e);
            let (t1, t2) = fm.edge_tris[e];
            for t in [Some(t1), t2].into_iter().flatten() {
                let ct = parent[t];
                let phi = Element::phi(Element::new(coarse, ct).bary(m));
                terms.extend(phi.iter().enumerate().map(|(i, &p)| (coarse.tri_edges[ct][i], p)));
            }
            start.push(terms.len());
        }
        Prolongation { start, terms }
    }

    /// P u_c on the fine space, from the coarse unknowns `u_c`: on each fine edge the mean over its
    /// parents of Σ_i φ_i(m) u_c(coarse edge i).
    pub fn apply(&self, coarse: &CrSpace, u_c: &[f64], fine: &CrSpace) -> Vec<f64> {
        let mid = coarse.midpoint_values(u_c);
        let mut u = vec![0.0; fine.n_dofs];
        for (e, dof) in fine.edge_dof.iter().enumerate() {
            if dof.terms().next().is_none() {
                continue;
            }
            let v = self.at(e, &mid);
            for (k, c) in dof.terms() {
                u[k] = c[0] * v[0] + c[1] * v[1];
            }
        }
        u
    }

    /// P U_c on the full midpoint fields: from the coarse displacement at every coarse edge midpoint
    /// (the lifting of boundary data included, `CrSpace::displacement`) to the value at every fine edge
    /// midpoint, constrained edges included.
    pub fn apply_full(&self, mid: &[[f64; 2]]) -> Vec<[f64; 2]> {
        (0..self.start.len() - 1).map(|e| self.at(e, mid)).collect()
    }

    /// Fine edge e's value: the mean over its parents of Σ_i φ_i(m) mid(coarse edge i).
    fn at(&self, e: usize, mid: &[[f64; 2]]) -> [f64; 2] {
        let terms = &self.terms[self.start[e]..self.start[e + 1]];
        let mut sum = [0.0; 2];
        for &(c, p) in terms {
            let v = mid[c];
            sum = [sum[0] + p * v[0], sum[1] + p * v[1]];
        }
        let count = (terms.len() / 3) as f64;
        [sum[0] / count, sum[1] / count]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Diagonal, MeshSpec, Part, PartKind};

    #[test]
    fn prolongation_reproduces_affine_fields_and_is_exact_on_nested_meshes() {
        let parts: Vec<Part> = ["bottom", "right", "top", "left"]
            .iter()
            .map(|n| Part { name: n.to_string(), kind: PartKind::Neumann(None) })
            .collect();
        let c = [[0.0, 0.0], [2.0, 0.5], [2.5, 2.0], [0.5, 1.5]];
        let mk = |n| {
            Mesh::from_spec(&MeshSpec::Structured { corners: c, cells: [n, n], diagonal: Diagonal::First, refine: 0 })
                .unwrap()
        };
        let (cm, fm) = (mk(3), mk(6));
        let (cs, fs) = (CrSpace::new(&cm, &parts).unwrap(), CrSpace::new(&fm, &parts).unwrap());
        // a parallelogram, so refining the structured mesh nests it; affine fields are CR on both meshes
        let f = |p: [f64; 2]| [0.3 * p[0] - 0.2 * p[1] + 0.1, 0.7 * p[1] + 0.05 * p[0] - 0.3];
        let mut uc = vec![0.0; cs.n_dofs];
        for (e, d) in cs.edge_dof.iter().enumerate() {
            let v = f(cm.midpoint(e));
            for (k, co) in d.terms() {
                uc[k] = co[0] * v[0] + co[1] * v[1];
            }
        }
        let uf = prolong((&cm, &cs), &uc, (&fm, &fs)).unwrap();
        for (e, d) in fs.edge_dof.iter().enumerate() {
            let v = f(fm.midpoint(e));
            for (k, co) in d.terms() {
                assert!((uf[k] - (co[0] * v[0] + co[1] * v[1])).abs() < 1e-13);
            }
        }
    }
}

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

/// A centroid whose smallest barycentric coordinate in a coarse triangle is at least this lies inside it
/// by far more than rounding (the mesh check bounds the aspect ratio by 1e12, so the coordinates' rounding
/// stays below 1e-4): no other triangle contains it, so point location would return that triangle. A
/// centroid of nested red or structured refinement has at least 1/(3·2^k) in its parent k levels up.
const INSIDE: f64 = 1e-3;

/// For every fine triangle, the coarse triangle containing its centroid (nested meshes).
pub fn parent_triangles(coarse: &Mesh, fine: &Mesh) -> Result<Vec<usize>> {
    parents_counted(coarse, fine).map(|(p, _)| p)
}

/// [`parent_triangles`], and how many centroids needed point location. A centroid is first tried in the
/// parents of the fine triangle before it and of its fine neighbours found already and in their coarse
/// neighbours (nested refinement numbers the children of a coarse triangle together or row by row), then
/// found by walking from the last parent towards it, across the edge of the most negative barycentric
/// coordinate; a triangle it is [`INSIDE`] is its parent, the triangle point location gives. Only
/// centroids the walk misses (a non-convex domain stops it at the boundary) are located (the bucket grid
/// is built at the first).
pub fn parents_counted(coarse: &Mesh, fine: &Mesh) -> Result<(Vec<usize>, usize)> {
    let elements: Vec<Element> = (0..coarse.tris.len()).map(|t| Element::new(coarse, t)).collect();
    let inside = |t: usize, x: [f64; 2]| {
        let l = elements[t].bary(x);
        l[0].min(l[1]).min(l[2]) >= INSIDE
    };
    // the triangle across edge i of t (opposite its vertex i)
    let across = |t: usize, i: usize| match coarse.edge_tris[coarse.tri_edges[t][i]] {
        (t1, t2) if t1 == t => t2,
        (t1, _) => Some(t1),
    };
    let around = |t: usize| std::iter::once(t).chain((0..3).filter_map(move |i| across(t, i)));
    let walk = |mut t: usize, x: [f64; 2]| {
        for _ in 0..=coarse.tris.len() {
            let l = elements[t].bary(x);
            let i = (0..3).min_by(|&a, &b| l[a].total_cmp(&l[b])).unwrap_or(0);
            match across(t, i) {
                _ if l[i] >= INSIDE => return Some(t),
                Some(next) if l[i] < 0.0 => t = next,
                _ => return None,
            }
        }
        None
    };
    let mut loc = None;
    let (mut parents, mut located): (Vec<usize>, usize) = (Vec::with_capacity(fine.tris.len()), 0);
    for t in 0..fine.tris.len() {
        let [a, b, c] = fine.tris[t].map(|v| fine.points[v]);
        let centroid = [(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0];
        let done = |u: usize| (u < t).then(|| parents[u]);
        let known = fine.tri_edges[t].map(|e| match fine.edge_tris[e] {
            (t1, t2) if t1 == t => t2.and_then(done),
            (t1, _) => done(t1),
        });
        let last = t.checked_sub(1).map_or(0, |u| parents[u]);
        let seeds = std::iter::once(last).chain(known.into_iter().flatten());
        let near = seeds.flat_map(around).find(|&g| inside(g, centroid));
        if let Some(g) = near.or_else(|| walk(last, centroid)) {
            parents.push(g);
            continue;
        }
        located += 1;
        let found = loc.get_or_insert_with(|| Locator::new(coarse)).find(centroid);
        parents.push(found.map(|(ct, _)| ct).ok_or_else(|| {
            Error::mesh(
                &fine.source,
                format!("fine triangle at ({:.6}, {:.6}) lies outside the coarse mesh", centroid[0], centroid[1]),
            )
        })?);
    }
    Ok((parents, located))
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

    /// The parents by point location alone (the method before the walk).
    fn located(coarse: &Mesh, fine: &Mesh) -> Vec<usize> {
        let loc = Locator::new(coarse);
        (0..fine.tris.len())
            .map(|t| {
                let [a, b, c] = fine.tris[t].map(|v| fine.points[v]);
                loc.find([(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]).unwrap().0
            })
            .collect()
    }

    /// Requirement (the planner's own CPU): the system shall find the parents of nested
    /// meshes' triangles (structured refinement of a parallelogram with either diagonal, one and two
    /// levels; red refinement of a quadrilateral's mesh) without point location, and give the parents of
    /// point location on every mesh pair, nested or not (a bilinear quadrilateral's structured meshes).
    #[test]
    fn parents_are_found_without_point_location_on_nested_meshes() {
        let para = [[0.0, 0.0], [2.0, 0.5], [2.5, 2.0], [0.5, 1.5]];
        let quad = [[0.0, 0.0], [2.0, 0.3], [2.6, 2.4], [0.2, 1.5]];
        let mk = |c, [n, m]: [usize; 2], diagonal| {
            Mesh::from_spec(&MeshSpec::Structured { corners: c, cells: [n, m], diagonal, refine: 0 }).unwrap()
        };
        for d in [Diagonal::First, Diagonal::Second] {
            for (n, f) in [([3, 4], [6, 8]), ([3, 4], [12, 16]), ([5, 2], [10, 4])] {
                let (cm, fm) = (mk(para, n, d), mk(para, f, d));
                let (p, count) = parents_counted(&cm, &fm).unwrap();
                assert_eq!(p, located(&cm, &fm), "{d:?} {n:?} -> {f:?}");
                assert_eq!(count, 0, "{d:?} {n:?} -> {f:?}: point location on nested meshes");
            }
            let (cm, fm) = (mk(quad, [4, 4], d), mk(quad, [8, 8], d));
            assert_eq!(parents_counted(&cm, &fm).unwrap().0, located(&cm, &fm), "bilinear {d:?}");
        }
        let raw = crate::mesh::structured_raw(&quad, [3, 4], Diagonal::First).unwrap();
        let once = crate::mesh::refine::red(&raw);
        let (cm, fm) = (Mesh::build(once.clone()).unwrap(), Mesh::build(crate::mesh::refine::red(&once)).unwrap());
        let (p, count) = parents_counted(&cm, &fm).unwrap();
        assert_eq!((p, count), (located(&cm, &fm), 0), "red refinement");
    }
}

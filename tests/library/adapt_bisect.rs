//! Newest-vertex bisection (src/mesh/bisect.rs): conformity, boundary tags, nestedness, minimum angle,
//! Dörfler marking, on a structured mesh and on the Gmsh L-shape of verification/cases.

use std::path::PathBuf;
use tresca_cr::fem::prolong::prolong;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::bisect::{bisect, descendant_min_angle, dorfler, label_longest_edge, to_raw};
use tresca_cr::mesh::{raw_from_spec, Mesh, RawMesh};
use tresca_cr::scene::{Diagonal, MeshSpec, Part, PartKind};

fn structured() -> RawMesh {
    let c = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]];
    raw_from_spec(&MeshSpec::Structured { corners: c, cells: [2, 2], diagonal: Diagonal::First, refine: 0 }).unwrap()
}

fn lshape() -> RawMesh {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("verification/cases/lshape.msh");
    raw_from_spec(&MeshSpec::Gmsh { path, refine: 0 }).unwrap()
}

fn labelled(mut raw: RawMesh) -> Mesh {
    label_longest_edge(&mut raw);
    Mesh::build(raw).unwrap()
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Tagged length per tag.
fn tagged_length(m: &Mesh) -> Vec<f64> {
    let mut l = vec![0.0; m.tag_names.len()];
    for e in 0..m.edges.len() {
        if let Some(t) = m.edge_tag[e] {
            l[t] += m.edge_length(e);
        }
    }
    l
}

/// Mark the triangles having a vertex at `p`.
fn at_point(m: &Mesh, p: [f64; 2]) -> Vec<bool> {
    m.tris.iter().map(|t| t.iter().any(|&v| dist(m.points[v], p) < 1e-12)).collect()
}

/// Checks of one refinement step from `coarse` with `marked`; returns the fine mesh.
fn refine_checked(coarse: &Mesh, marked: &[bool]) -> Mesh {
    let (raw, parent) = bisect(coarse, marked);
    let fine = Mesh::build(raw.clone()).expect("the bisected mesh is a valid mesh");
    // conforming: no hanging vertex, so an edge with one triangle lies on the boundary, i.e. is tagged
    // (every boundary edge of these meshes is in a part); Mesh::build already refused edges in > 2 triangles
    for e in 0..fine.edges.len() {
        assert_eq!(fine.edge_tris[e].1.is_none(), fine.edge_tag[e].is_some(), "hanging vertex at edge {e}");
    }
    // every marked triangle was split
    for (t, _) in marked.iter().enumerate().filter(|m| *m.1) {
        assert!(parent.iter().filter(|&&p| p == t).count() >= 2, "marked triangle {t} not split");
    }
    // tags preserved: tagged length per part unchanged (to rounding: sums of halves)
    for (a, b) in tagged_length(coarse).iter().zip(tagged_length(&fine)) {
        assert!((a - b).abs() <= 1e-12 * a.max(1.0), "tagged length {a} became {b}");
    }
    // nested: each child's vertices inside its parent (barycentric coordinates ≥ 0 up to rounding) and the
    // children's areas sum to the parent's
    let mut area = vec![0.0; coarse.tris.len()];
    for (t, &p) in parent.iter().enumerate() {
        let el = tresca_cr::fem::space::Element::new(coarse, p);
        for &v in &fine.tris[t] {
            let l = el.bary(fine.points[v]);
            assert!(l.iter().all(|&x| x >= -1e-12), "child {t} leaves its parent {p}: {l:?}");
        }
        area[p] += fine.area(t);
    }
    for (t, a) in area.iter().enumerate() {
        assert!((a - coarse.area(t)).abs() <= 1e-12 * coarse.area(t), "areas of the children of {t}");
    }
    fine
}

/// The system shall refine marked triangles of structured and Gmsh meshes into a conforming, nested
/// mesh whose boundary parts keep their lengths.
#[test]
fn bisection_is_conforming_nested_and_keeps_tags() {
    for raw in [structured(), lshape()] {
        let mut m = labelled(raw);
        for level in 0..6 {
            // a scattered marking: every third triangle, shifted per level
            let marked: Vec<bool> = (0..m.tris.len()).map(|t| (t + level) % 3 == 0).collect();
            m = refine_checked(&m, &marked);
        }
        assert!(m.tris.len() > 100);
    }
}

/// The system shall keep the minimum angle bounded over 20 refinements at a corner: above the smallest
/// angle of the first 6 generations of bisection of each initial triangle (NVB's finitely many
/// similarity classes, at most 4 per triangle, appear within them), and exactly 45° on the structured
/// mesh of right isosceles triangles bisected at their hypotenuses.
#[test]
fn minimum_angle_stays_bounded_at_a_refined_corner() {
    for (raw, corner, exact45) in [(structured(), [0.0, 0.0], true), (lshape(), [1.0, 1.0], false)] {
        let mut m = labelled(raw);
        let bound =
            m.tris.iter().map(|t| descendant_min_angle(t.map(|v| m.points[v]), 6)).fold(f64::INFINITY, f64::min);
        let n0 = m.tris.len();
        for _ in 0..20 {
            let marked = at_point(&m, corner);
            assert!(marked.iter().any(|&x| x), "the corner is a vertex of the mesh");
            m = refine_checked(&m, &marked);
            let angle = m.min_angle();
            // 1e-9°: rounding of the angles of triangles with sides down to 2^-10 of the initial ones
            assert!(angle >= bound - 1e-9, "min angle {angle} below the NVB bound {bound}");
            if exact45 {
                assert!((angle - 45.0).abs() < 1e-9, "min angle {angle}, expected 45");
            }
        }
        // local: the triangle count grows by a bounded amount per level, not fourfold
        assert!(m.tris.len() < n0 + 20 * 60, "{} triangles after 20 corner refinements", m.tris.len());
        let h_min = (0..m.edges.len()).map(|e| m.edge_length(e)).fold(f64::INFINITY, f64::min);
        assert!(h_min < 1e-2, "refinement reached the corner: smallest edge {h_min}");
    }
}

/// The system shall mark by Dörfler's rule the fewest largest indicators carrying θ of the total.
#[test]
fn dorfler_marks_the_fewest_largest() {
    let eta2 = [1.0, 9.0, 4.0, 0.5, 4.0, 0.25];
    let m = dorfler(&eta2, 0.5); // total 18.75, 9 < 9.375 so 9 and both 4s (tie kept)
    assert_eq!(m, [false, true, true, false, true, false]);
    assert_eq!(dorfler(&eta2, 0.4), [false, true, false, false, false, false]);
    assert!(dorfler(&eta2, 1.0).iter().all(|&x| x));
}

/// The system shall prolongate CR fields across adapted (nested) levels: affine fields exactly.
#[test]
fn prolongation_is_exact_for_affine_fields_across_adapted_levels() {
    let coarse = labelled(lshape());
    let marked = at_point(&coarse, [1.0, 1.0]);
    let (raw, _) = bisect(&coarse, &marked);
    let fine = Mesh::build(raw).unwrap();
    let fine = Mesh::build(bisect(&fine, &at_point(&fine, [1.0, 1.0])).0).unwrap();
    let parts: Vec<Part> =
        coarse.tag_names.iter().map(|n| Part { name: n.clone(), kind: PartKind::Neumann(None) }).collect();
    let (cs, fs) = (CrSpace::new(&coarse, &parts).unwrap(), CrSpace::new(&fine, &parts).unwrap());
    let f = |p: [f64; 2]| [0.3 * p[0] - 0.2 * p[1] + 0.1, 0.7 * p[1] + 0.05 * p[0] - 0.3];
    let fill = |m: &Mesh, s: &CrSpace| {
        let mut u = vec![0.0; s.n_dofs];
        for (e, d) in s.edge_dof.iter().enumerate() {
            let v = f(m.midpoint(e));
            for (k, c) in d.terms() {
                u[k] = c[0] * v[0] + c[1] * v[1];
            }
        }
        u
    };
    let uf = prolong((&coarse, &cs), &fill(&coarse, &cs), (&fine, &fs)).unwrap();
    for (a, b) in uf.iter().zip(fill(&fine, &fs)) {
        assert!((a - b).abs() < 1e-13, "{a} vs {b}");
    }
    let _ = to_raw(&fine);
}

/// The system shall write an adapted mesh as Gmsh 4.1 that reads back (mesh::parse_gmsh) to the same
/// points (bit for bit), triangles and boundary parts.
#[test]
fn adapted_mesh_round_trips_through_gmsh() {
    let mut m = labelled(lshape());
    for _ in 0..3 {
        m = Mesh::build(bisect(&m, &at_point(&m, [1.0, 1.0])).0).unwrap();
    }
    let text = tresca_cr::adapt::export::gmsh_text(&m);
    let back = Mesh::build(tresca_cr::mesh::parse_gmsh(&text, "adapted.msh").unwrap()).unwrap();
    // the reader numbers the vertices in the order the triangles use them: map them back by their bits
    let index: std::collections::HashMap<[u64; 2], usize> =
        m.points.iter().enumerate().map(|(i, p)| (p.map(f64::to_bits), i)).collect();
    assert_eq!(back.points.len(), m.points.len());
    let to_m: Vec<usize> = back.points.iter().map(|p| index[&p.map(f64::to_bits)]).collect();
    let tris: Vec<[usize; 3]> = back.tris.iter().map(|t| t.map(|v| to_m[v])).collect();
    assert_eq!(tris, m.tris);
    assert_eq!(back.tag_names, m.tag_names);
    assert_eq!(tagged_length(&back), tagged_length(&m));
}

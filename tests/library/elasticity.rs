//! Requirements of the core issue: the stabilised CR elasticity solver without contact.

use crate::common;
use common::*;
use tresca_cr::fem::assemble::stiffness;
use tresca_cr::fem::elasticity::Elasticity;
use tresca_cr::fem::space::CrSpace;
use tresca_cr::mesh::{Mesh, RawMesh};
use tresca_cr::scene::{Part, PartKind};
use tresca_cr::sparse::matvec;
use tresca_cr::{Problem, Scene};

/// Affine field u = (a x, b x) (zero on x = 0) with σ constant; tractions σn on the other sides.
fn patch_scene(mesh_toml: &str, sides: &[(&str, [f64; 2])], clamp: &str) -> (Scene, [f64; 2]) {
    let (a, b) = (0.3, -0.2);
    let (e, nu) = (70.0, 0.25);
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    // ε11 = a, ε12 = b/2, ε22 = 0
    let s = [[(lam + 2.0 * mu) * a, mu * b], [mu * b, lam * a]];
    let mut text = format!("{mesh_toml}\n[material]\nE = {e}\nnu = {nu}\n[time]\nT = 1.0\nsteps = 1\n[exact]\nu = [\"{a}*x\", \"{b}*x\"]\ngrad = [[\"{a}\", \"0\"], [\"{b}\", \"0\"]]\n");
    text += &format!("[[boundary]]\nname = \"{clamp}\"\nkind = \"dirichlet\"\n");
    for (name, n) in sides {
        let t = [s[0][0] * n[0] + s[0][1] * n[1], s[1][0] * n[0] + s[1][1] * n[1]];
        text += &format!(
            "[[boundary]]\nname = \"{name}\"\nkind = \"neumann\"\ntraction = [\"{:?}\", \"{:?}\"]\n",
            t[0], t[1]
        );
    }
    (Scene::from_str(&text, "patch").unwrap(), [a, b])
}

fn jitter(raw: &mut RawMesh, amount: f64) {
    let mut state: u64 = 0x9E3779B97F4A7C15;
    let mut rnd = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let on_boundary: std::collections::HashSet<usize> =
        raw.tagged.iter().flat_map(|(e, _)| e.iter().copied()).collect();
    for (i, p) in raw.points.iter_mut().enumerate() {
        if !on_boundary.contains(&i) {
            p[0] += amount * rnd();
            p[1] += amount * rnd();
        }
    }
}

fn check_patch(scene: Scene, mesh: Mesh, ab: [f64; 2]) {
    let p = Problem::with_mesh(scene, mesh).unwrap();
    let mut worst: f64 = 0.0;
    p.run(tresca_cr::RunOptions::all(), |r| {
        if r.n == 1 {
            let mid = p.space.midpoint_values(&r.u);
            for (e, m) in mid.iter().enumerate() {
                let x = p.mesh.midpoint(e)[0];
                worst = worst.max((m[0] - ab[0] * x).abs()).max((m[1] - ab[1] * x).abs());
            }
            let err = r.errors.unwrap();
            assert!(err.energy < 1e-11 && err.l2 < 1e-12, "{}: {err:?}", p.mesh.source);
        }
        Ok(())
    })
    .unwrap();
    // the affine field lies in V_h and a_h is consistent for it: only rounding remains
    assert!(worst < 1e-12, "patch test: max midpoint deviation {worst:e}");
}

/// The solver shall reproduce any affine displacement with matching tractions to 1e-12 on unstructured meshes.
#[test]
fn patch_test_on_unstructured_meshes() {
    // a jittered structured mesh (every interior vertex moved, all angles different)
    let mesh_toml = "[mesh]\ncorners = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]]\ncells = [8, 4]";
    let sides = [("bottom", [0.0, -1.0]), ("right", [1.0, 0.0]), ("top", [0.0, 1.0])];
    let (scene, ab) = patch_scene(mesh_toml, &sides, "left");
    let c = [[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]];
    let mut raw = tresca_cr::mesh::structured_raw(&c, [8, 4], tresca_cr::scene::Diagonal::First).unwrap();
    jitter(&mut raw, 0.12);
    check_patch(scene, Mesh::build(raw).unwrap(), ab);
    // a Gmsh L-shape, as read and after one red refinement
    for refine in [0, 1] {
        let mesh_toml = format!(
            "[mesh]\nfile = \"{}/verification/cases/lshape.msh\"\nrefine = {refine}",
            env!("CARGO_MANIFEST_DIR")
        );
        // L-shape: floor y=0 (n = (0,-1)); "loaded" has several normals, so apply the traction per edge via
        // the exact σn: split into a scene whose loaded part is traction free is not affine-consistent,
        // so use an L-shape-specific traction expression that is piecewise by position.
        let (scene, ab) = lshape_patch_scene(&mesh_toml);
        let mesh = Mesh::from_spec(&scene.mesh).unwrap();
        check_patch(scene, mesh, ab);
    }
}

/// The L-shape's "loaded" part has normals (1,0) at x = 2, (0,1) at y = 1 (x > 1), (1,0) at x = 1 (y > 1),
/// (0,1) at y = 2: the traction σn is written piecewise with the solver's min/max functions.
fn lshape_patch_scene(mesh_toml: &str) -> (Scene, [f64; 2]) {
    let (a, b) = (0.3, -0.2);
    let (e, nu) = (70.0, 0.25);
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let s = [[(lam + 2.0 * mu) * a, mu * b], [mu * b, lam * a]];
    // indicator of a vertical side (normal (1,0)): x = 2, or x = 1 with y > 1; otherwise horizontal (0,1)
    let vertical =
        "0.5*(1 + signum(x - 1.999999)) + 0.25*(1 + signum(0.000001 - abs(x - 1)))*(1 + signum(y - 1.000001))";
    let tx = format!("({v})*({:?}) + (1 - ({v}))*({:?})", s[0][0], s[0][1], v = vertical);
    let ty = format!("({v})*({:?}) + (1 - ({v}))*({:?})", s[1][0], s[1][1], v = vertical);
    let floor = [-s[0][1], -s[1][1]];
    let text = format!(
        "{mesh_toml}\n[material]\nE = {e}\nnu = {nu}\n[time]\nT = 1.0\nsteps = 1\n[exact]\nu = [\"{a}*x\", \"{b}*x\"]\ngrad = [[\"{a}\", \"0\"], [\"{b}\", \"0\"]]\n\
         [[boundary]]\nname = \"clamp\"\nkind = \"dirichlet\"\n[[boundary]]\nname = \"floor\"\nkind = \"neumann\"\ntraction = [\"{:?}\", \"{:?}\"]\n\
         [[boundary]]\nname = \"loaded\"\nkind = \"neumann\"\ntraction = [\"{tx}\", \"{ty}\"]\n",
        floor[0], floor[1]
    );
    (Scene::from_str(&text, "lshape patch").unwrap(), [a, b])
}

/// a_h(r, r) = 0 for the rigid motions when no Dirichlet part exists; with one, K is SPD.
#[test]
fn rigid_motions_are_in_the_kernel_and_clamping_makes_k_spd() {
    let c = [[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [0.0, 2.0]];
    let raw = tresca_cr::mesh::structured_raw(&c, [6, 4], tresca_cr::scene::Diagonal::Second).unwrap();
    let mesh = Mesh::build(raw).unwrap();
    let mat = tresca_cr::scene::Material { e: 10.0, nu: 0.3 };
    let free: Vec<Part> = ["bottom", "right", "top", "left"]
        .iter()
        .map(|n| Part { name: n.to_string(), kind: PartKind::Neumann(None) })
        .collect();
    let space = CrSpace::new(&mesh, &free).unwrap();
    let k = stiffness(&mesh, &space, &Elasticity::new(&mat), 10.0);
    let norm_k = k.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for r in [|_x: f64, _y: f64| [1.0, 0.0], |_x, _y| [0.0, 1.0], |x: f64, y: f64| [-y, x]] {
        let u: Vec<f64> = (0..mesh.edges.len()).flat_map(|e| r(mesh.midpoint(e)[0], mesh.midpoint(e)[1])).collect();
        let mut ku = vec![0.0; u.len()];
        matvec(&k, &u, &mut ku);
        let a: f64 = u.iter().zip(&ku).map(|(x, y)| x * y).sum();
        let uu: f64 = u.iter().map(|x| x * x).sum();
        assert!(a.abs() < 1e-12 * norm_k * uu, "a_h(r, r) = {a:e}");
    }
    // a strain mode is not in the kernel
    let u: Vec<f64> = (0..mesh.edges.len()).flat_map(|e| [mesh.midpoint(e)[0], 0.0]).collect();
    let mut ku = vec![0.0; u.len()];
    matvec(&k, &u, &mut ku);
    assert!(u.iter().zip(&ku).map(|(x, y)| x * y).sum::<f64>() > 1.0);
    // with a clamped side the dense matrix is SPD: smallest eigenvalue positive
    let mut clamped = free.clone();
    clamped[3].kind = PartKind::Dirichlet(None);
    let space = CrSpace::new(&mesh, &clamped).unwrap();
    let k = stiffness(&mesh, &space, &Elasticity::new(&mat), 10.0);
    let n = space.n_dofs;
    let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let mut col = vec![0.0; n];
        matvec(&k, &e, &mut col);
        for i in 0..n {
            dense[(i, j)] = col[i];
        }
    }
    assert!((&dense - dense.transpose()).amax() < 1e-12 * dense.amax(), "K is not symmetric");
    let eig = nalgebra::SymmetricEigen::new(dense).eigenvalues;
    let (lo, hi) = (eig.min(), eig.max());
    assert!(lo > 1e-8 * hi, "smallest eigenvalue {lo:e} vs largest {hi:e}");
}

/// The paper's meshes on (0,4)² with the right side clamped give DOF 28, 104, 400, 1568, 6208.
#[test]
fn paper_dof_counts() {
    let mut s = scene("verification/cases/paper_example_5_1.toml");
    for (k, want) in [28, 104, 400, 1568, 6208].into_iter().enumerate() {
        s.set_refine(k as u32).unwrap();
        let mesh = Mesh::from_spec(&s.mesh).unwrap();
        let space = CrSpace::new(&mesh, &s.parts).unwrap();
        assert_eq!(space.paper_dofs(), want, "n = {}", 2 << k);
        assert_eq!(space.n_dofs, want - space.contact.len(), "contact normal components are eliminated");
    }
}

fn elastic_rates(path: &str) {
    let levels = 2..=6u32; // h = h0/4 .. h0/64: 5 levels, 4 ratios
    let (mut h, mut en, mut l2) = (vec![], vec![], vec![]);
    for k in levels {
        let mut s = scene(path);
        s.set_refine(k).unwrap();
        let (p, steps) = run(s);
        let (e, l) = max_errors(&steps);
        h.push(p.mesh.h_max());
        en.push(e);
        l2.push(l);
    }
    print_table(path, &h, &[("energy", &en), ("L2", &l2)]);
    let (re, rl) = (successive_rates(&h, &en), successive_rates(&h, &l2));
    let (fe, fl) = (fitted_rate(&h, &en), fitted_rate(&h, &l2));
    println!("fitted: energy {fe:.3}, L2 {fl:.3}");
    // asymptotic range: the last two successive orders agree with the fit (within the same band)
    assert!(
        (fe - 1.0).abs() <= 0.1 && re.iter().skip(1).all(|r| (r - 1.0).abs() <= 0.1),
        "energy orders {re:?}, fit {fe}"
    );
    assert!(
        (fl - 2.0).abs() <= 0.15 && re.len() >= 4 && rl.iter().skip(1).all(|r| (r - 2.0).abs() <= 0.15),
        "L2 orders {rl:?}, fit {fl}"
    );
}

/// The solver shall converge with order 1 ± 0.1 (energy) and 2 ± 0.15 (L²) on a smooth manufactured
/// elasticity problem on a rectangle.
#[test]
fn manufactured_elasticity_rates_rectangle() {
    elastic_rates("verification/cases/elastic_rect.toml");
}

/// ... and on a rotated square.
#[test]
fn manufactured_elasticity_rates_rotated_square() {
    elastic_rates("verification/cases/elastic_rotated.toml");
}

/// Requirement (issue 13, assembly straight into compressed columns): K equals the entry-by-entry sum of
/// every element and jump contribution a_h(ψ_j, ψ_i) (the former triplet route, kept here as the
/// oracle) on a rotated mesh whose Γ_C unknowns are tangential (non-axis directions) and with Γ_D
/// edges; its pattern is the mesh's (`EdgePattern::unknown_pattern`, from which the symbolic
/// factorisation is computed before K's values exist: every unknown of two coupled edges, the zero x–y
/// couplings of jump-only neighbours included), with sorted columns, symmetric (the element blocks'
/// λ g_x g_y + μ g_y g_x is not bitwise symmetric, as before; the factor reads one triangle, and a run
/// keeps that lower triangle, the same bit for bit as the matrix assembled on both). Tolerance: the two routes sum the
/// same products in a different order, so entries agree to a few ulps of the largest entry.
#[test]
fn compressed_assembly_equals_the_sum_of_contributions() {
    use tresca_cr::fem::quadrature::GAUSS2;
    use tresca_cr::fem::space::{jump_terms, Element};
    let scene = Scene::from_file(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/verification/cases/mms_rotated.toml"
    )))
    .unwrap();
    let p = Problem::new(scene).unwrap();
    let (mesh, space, k) = (&p.mesh, &p.space, &p.stiffness);
    assert!(!space.contact.is_empty() && space.n_dirichlet > 0);
    let law = Elasticity::new(&p.scene.material);
    let mut trip = Vec::new();
    let mut push = |a: usize, b: usize, m: [[f64; 2]; 2]| {
        for (r, v) in space.edge_dof[a].terms() {
            for (c, w) in space.edge_dof[b].terms() {
                let x =
                    (0..2).flat_map(|i| (0..2).map(move |j| (i, j))).map(|(i, j)| v[i] * m[i][j] * w[j]).sum::<f64>();
                trip.push((r, c, x));
            }
        }
    };
    for t in 0..mesh.tris.len() {
        let el = Element::new(mesh, t);
        for i in 0..3 {
            for j in 0..3 {
                push(
                    mesh.tri_edges[t][i],
                    mesh.tri_edges[t][j],
                    law.element_block(el.area, el.grad_phi(i), el.grad_phi(j)),
                );
            }
        }
    }
    for e in (0..mesh.edges.len()).filter(|&e| space.is_stabilised(mesh, e)) {
        for (s, w) in GAUSS2 {
            let terms = jump_terms(mesh, e, s);
            for &(a, pa) in &terms {
                for &(b, pb) in &terms {
                    let x = 2.0 * p.scene.rho * law.mu * w * pa * pb;
                    push(a, b, [[x, 0.0], [0.0, x]]);
                }
            }
        }
    }
    let n = space.n_dofs;
    let mut dense = vec![0.0f64; n * n];
    for (r, c, x) in trip {
        dense[r * n + c] += x;
    }
    let scale = dense.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut stored = vec![0.0f64; n * n];
    // the run keeps K's lower triangle: the one of K assembled on both, bit for bit
    let full = stiffness(mesh, space, &law, p.scene.rho);
    let lower = tresca_cr::sparse::lower_pattern(full.symbolic());
    assert_eq!((k.symbolic().col_ptr(), k.symbolic().row_idx()), (lower.col_ptr(), lower.row_idx()));
    assert_eq!(k.val(), tresca_cr::sparse::lower_values(full.symbolic(), full.val().to_vec()).as_slice());
    let k = &full;
    let (cp, ri) = (k.symbolic().col_ptr(), k.symbolic().row_idx());
    let mesh_pattern = tresca_cr::fem::assemble::EdgePattern::new(mesh).unknown_pattern(space);
    assert_eq!((cp, ri), (mesh_pattern.col_ptr(), mesh_pattern.row_idx()), "K's pattern is not the mesh's");
    for j in 0..n {
        assert!(ri[cp[j]..cp[j + 1]].windows(2).all(|w| w[0] < w[1]), "column {j} not sorted");
        for q in cp[j]..cp[j + 1] {
            stored[ri[q] * n + j] = k.val()[q];
        }
    }
    for i in 0..n {
        for j in 0..n {
            assert!((stored[i * n + j] - stored[j * n + i]).abs() <= 1e-14 * scale, "asymmetric at ({i}, {j})");
            let d = (stored[i * n + j] - dense[i * n + j]).abs();
            assert!(
                d <= 1e-14 * scale,
                "K[{i}, {j}] = {:e}, contributions sum to {:e}",
                stored[i * n + j],
                dense[i * n + j]
            );
        }
    }
}

/// Requirement (issue 13, ordering beside assembly): the graph of the unknowns taken from the mesh before
/// K's values exist is the graph read from K, so the fill-reducing ordering computed from it (on a
/// second thread while K is assembled) is the one K would give, and results do not change.
#[test]
fn graph_from_the_mesh_is_the_graph_of_k() {
    use tresca_cr::fem::assemble::EdgePattern;
    use tresca_cr::solve::cholesky::Graph;
    for case in ["mms_rotated", "paper_example_5_1", "mms_stop"] {
        let path = format!("{}/verification/cases/{case}.toml", env!("CARGO_MANIFEST_DIR"));
        let p = Problem::new(Scene::from_file(std::path::Path::new(&path)).unwrap()).unwrap();
        let (first, start, adj) = EdgePattern::new(&p.mesh).unknown_graph(&p.space);
        let from_mesh = Graph::new(first, start, adj).expect("consistent graph");
        assert_eq!(from_mesh, Graph::of_matrix(&p.stiffness, &p.space.unknown_groups()), "{case}");
    }
}

/// Requirement (issue 44, phase 1 without waiting for K's pattern): the symbolic factorisation made from
/// the graph of the unknowns (`Symbolic::from_graph`, read as the pattern of its unknowns) shall be the
/// one made from K's pattern (`Symbolic::from_symmetric`): the same ordering and the same structure of L,
/// row indices in the same order, so the numeric factorisation and every result are unchanged.
#[test]
fn symbolic_from_the_graph_is_that_of_k() {
    use tresca_cr::fem::assemble::EdgePattern;
    use tresca_cr::solve::cholesky::{fill_order, Graph, Symbolic};
    for case in ["mms_rotated", "paper_example_5_1", "hertz_a05", "trapezoid", "floating_block", "lshape_adapt"] {
        let path = format!("{}/verification/cases/{case}.toml", env!("CARGO_MANIFEST_DIR"));
        let p = Problem::new(Scene::from_file(std::path::Path::new(&path)).unwrap()).unwrap();
        let pattern = EdgePattern::new(&p.mesh);
        let (first, start, adj) = pattern.unknown_graph(&p.space);
        let graph = Graph::new(first, start, adj).expect("consistent graph");
        let contact = p.space.contact_dofs();
        for nested in [false, true] {
            let order = fill_order(&graph, nested).unwrap();
            let full = pattern.unknown_pattern(&p.space);
            let of_k = Symbolic::from_symmetric(full.as_ref(), &contact, order.clone()).unwrap();
            let of_graph = Symbolic::from_graph(&graph, &contact, order).unwrap();
            assert!(of_k.same_structure(&of_graph), "{case}, nested dissection {nested}");
        }
    }
}

/// Requirement (issue 44, K assembled in its lower triangle): the values assembled directly in K's lower
/// triangle (`stiffness_values` with `Triangles::Lower` on `EdgePattern::unknown_pattern_lower`) shall be the lower triangle
/// of the full assembly, pattern and values bit for bit, with free edges, contact edges of one unknown
/// (tangential) and of two (a frame with a normal unknown).
#[test]
fn lower_triangle_assembled_directly_is_that_of_k() {
    use tresca_cr::fem::assemble::{stiffness_values, EdgePattern, Triangles};
    use tresca_cr::sparse::{lower_pattern, lower_values};
    for case in ["paper_example_5_1", "mms_signorini_stop", "mms_rotated", "trapezoid", "floating_block"] {
        let path = format!("{}/verification/cases/{case}.toml", env!("CARGO_MANIFEST_DIR"));
        let p = Problem::new(Scene::from_file(std::path::Path::new(&path)).unwrap()).unwrap();
        let (mesh, space, law, rho) = (&p.mesh, &p.space, &p.law, p.scene.rho);
        let pattern = EdgePattern::new(mesh);
        let full = pattern.unknown_pattern(space);
        let both = stiffness_values(&pattern, (full.as_ref(), Triangles::Both), mesh, space, law, rho);
        let expected = lower_values(full.as_ref(), both);
        let (expected_pattern, lower) = (lower_pattern(full.as_ref()), pattern.unknown_pattern_lower(space));
        assert_eq!(lower.col_ptr(), expected_pattern.col_ptr(), "{case}: column pointers");
        assert_eq!(lower.row_idx(), expected_pattern.row_idx(), "{case}: row indices");
        let got = stiffness_values(&pattern, (lower.as_ref(), Triangles::Lower), mesh, space, law, rho);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&got), bits(&expected), "{case}: values");
    }
}

//! Unilateral contact (Signorini) with Tresca and Coulomb friction, and symmetry parts: the scene keys
//! `law`, `coulomb`, `gap`, contact `traction` and `kind = "symmetry"` (docs/scene.md), the discrete
//! problem of docs/model.md ("Unilateral contact and Coulomb friction") and its refusals.

use crate::common;

use tresca_cr::{Problem, Scene, StepResult};

/// A unit block (ν = 0.3) on Γ_C = bottom, pressed through its top (Dirichlet, `TOP`), free sides.
const BLOCK: &str = r#"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [8, 8]
[material]
E = 200.0
nu = 0.3
[[boundary]]
name = "top"
kind = "dirichlet"
u = TOP
[[boundary]]
name = "left"
kind = "neumann"
[[boundary]]
name = "right"
kind = "neumann"
[[boundary]]
name = "bottom"
kind = "contact"
CONTACT
[time]
T = 1.0
steps = 4
"#;

fn block(top: &str, contact: &str) -> Scene {
    let text = BLOCK.replace("TOP", top).replace("CONTACT", contact);
    Scene::from_str(&text, "block.toml").unwrap_or_else(|e| panic!("{e}"))
}

fn run(s: Scene) -> Vec<StepResult> {
    common::run(s).1
}

fn max_abs(v: impl IntoIterator<Item = f64>) -> f64 {
    v.into_iter().fold(0.0, |a, x| a.max(x.abs()))
}

/// The system shall solve a block pressed onto the foundation with gap 0 and no friction as the
/// bilateral scene, the whole of Γ_C in contact: the same displacements and energies. Tolerance: each
/// step's natural residual is ≤ 1e-12 of its force scale, so the normal forces are within 1e-12 of it
/// times cond(C) (< 1e3 for the 16 contact unknowns of this mesh), and u within the same relative
/// amount: 1e-9 of max |u|.
#[test]
fn pressed_block_without_friction_is_the_bilateral_scene() {
    let top = r#"["0", "-0.01*t"]"#;
    let (pu, uni) = common::run(block(top, "law = \"unilateral\"\ng_a = \"0\""));
    let (pb, bi) = common::run(block(top, "g_a = \"0\""));
    let scale = max_abs(bi.iter().flat_map(|r| r.u.iter().copied()));
    for (a, b) in uni.iter().zip(&bi).skip(1) {
        let ua = pu.displacement(&a.u, a.t).unwrap();
        let ub = pb.displacement(&b.u, b.t).unwrap();
        let d = max_abs(ua.iter().zip(&ub).flat_map(|(x, y)| [x[0] - y[0], x[1] - y[1]]));
        assert!(d <= 1e-9 * scale, "step {}: |u_uni - u_bi| = {d:e} (max |u| {scale:e})", a.n);
        assert!((a.energy - b.energy).abs() <= 1e-9 * b.energy.abs(), "step {}", a.n);
        assert!(a.normal.separated.iter().all(|s| !s), "step {}: an edge separated", a.n);
        assert!(a.normal.force.iter().all(|&f| f > 0.0), "step {}: {:?}", a.n, a.normal.force);
    }
}

/// The system shall let a block lift off at one end: separated edges have p = 0 and an open gap,
/// contact edges a closed gap and p ≥ 0, and every step's KKT residual is within the tolerance.
/// Tolerance on a closed gap: the natural residual ≤ 1e-12 bounds |gap_e|/C_ee by 1e-12 of the force
/// scale, i.e. |gap_e| by 1e-12 of the free normal trace times cond(C) (< 1e3): 1e-9 of max |u|.
#[test]
fn lifting_block_separates_at_one_end() {
    let steps = run(block(r#"["0.002*t", "-0.01*t + 0.015*t*x"]"#, "law = \"unilateral\"\ng_a = \"0.05\""));
    let last = steps.last().unwrap();
    let scale = max_abs(last.u.iter().copied());
    let sep = last.normal.separated.iter().filter(|&&s| s).count();
    assert!(sep > 0 && sep < last.normal.separated.len(), "separated edges: {sep}");
    for r in &steps[1..] {
        assert!(r.residual <= 1e-12, "step {}: residual {:e}", r.n, r.residual);
        for ((&p, &g), &s) in r.normal.force.iter().zip(&r.normal.gap).zip(&r.normal.separated) {
            assert!(p >= 0.0 && g <= 1e-9 * scale, "step {}: P {p:e}, gap {g:e}", r.n);
            if s {
                assert!(p == 0.0 && g < 0.0, "step {}: separated with P {p:e}, gap {g:e}", r.n);
            } else {
                assert!(g.abs() <= 1e-9 * scale, "step {}: contact edge with gap {g:e}", r.n);
            }
        }
    }
    // separated at the lifted end (x near 1), in contact at the pressed one (x near 0)
    let p = common::run(block(r#"["0.002*t", "-0.01*t + 0.015*t*x"]"#, "law = \"unilateral\"\ng_a = \"0.05\"")).0;
    for (c, &s) in p.space.contact.iter().zip(&last.normal.separated) {
        let x = p.mesh.midpoint(c.edge)[0];
        assert!(x > 0.45 || !s, "the edge at x = {x} separated");
        assert!(x < 0.55 || s, "the edge at x = {x} is in contact");
    }
}

/// The system shall solve a `symmetry` part exactly as the frictionless bilateral contact part
/// (`kind = "contact"`, `g_a = "0"`): the same numbers, bit for bit.
#[test]
fn symmetry_is_frictionless_bilateral_contact_bit_for_bit() {
    let top = r#"["0.003*t", "-0.01*t"]"#;
    let sym = run(Scene::from_str(
        &BLOCK.replace("TOP", top).replace("kind = \"contact\"\nCONTACT", "kind = \"symmetry\""),
        "s.toml",
    )
    .unwrap());
    let con = run(block(top, "g_a = \"0\""));
    assert_eq!(sym.len(), con.len());
    for (a, b) in sym.iter().zip(&con) {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a.u), bits(&b.u), "step {}", a.n);
        assert_eq!(bits(&a.mu), bits(&b.mu), "step {}", a.n);
        assert_eq!(a.energy.to_bits(), b.energy.to_bits(), "step {}", a.n);
    }
}

/// The error of a scene that is refused (when read, set up or run).
fn refusal(text: &str) -> String {
    match Scene::from_str(text, "bad.toml") {
        Err(e) => e.to_string(),
        Ok(s) => match Problem::new(s) {
            Err(e) => e.to_string(),
            Ok(p) => p.run(tresca_cr::RunOptions::all(), |_| Ok(())).err().map(|e| e.to_string()).expect("accepted"),
        },
    }
}

fn refused(top: &str, contact: &str, extra: &str, needles: &[&str]) {
    let text = BLOCK.replace("TOP", top).replace("CONTACT", contact) + extra;
    let e = refusal(&text);
    for n in needles {
        assert!(e.contains(n), "`{contact}` / `{extra}`: message `{e}` lacks `{n}`");
    }
}

/// The system shall refuse, naming the part (and the point where pointwise): a penetrating initial
/// state, F < 0 or not finite, `coulomb` with `g_a`, `law`/`coulomb` on a part that is not a contact
/// part, an unknown law, keys on a symmetry part, and a body held only by contact.
#[test]
fn refusals_name_the_part() {
    let top = r#"["0", "-0.01"]"#;
    let u0 = "[initial]\nu0 = [\"0\", \"-0.01\"]\n";
    refused(top, "law = \"unilateral\"\ng_a = \"0\"", u0, &["bottom", "penetrates", "0.062500", "u0"]);
    refused(top, "law = \"unilateral\"\ncoulomb = \"-0.3\"", "", &["bottom", "coulomb", ">= 0"]);
    refused(top, "law = \"unilateral\"\ncoulomb = \"0.3*(x - 0.5)\"", "", &["bottom", "coulomb", "negative", "near ("]);
    refused(top, "law = \"unilateral\"\ncoulomb = \"sqrt(x - 2)\"", "", &["bottom", "coulomb", "NaN"]);
    refused(top, "coulomb = \"0.3\"\ng_a = \"0.1\"", "", &["bottom", "not both"]);
    refused(top, "law = \"sticky\"\ng_a = \"0\"", "", &["bottom", "unknown contact law `sticky`"]);
    let t = BLOCK.replace("TOP", top).replace("CONTACT", "g_a = \"0\"");
    let e = refusal(
        &t.replace("name = \"left\"\nkind = \"neumann\"", "name = \"left\"\nkind = \"neumann\"\nlaw = \"unilateral\""),
    );
    assert!(e.contains("left") && e.contains("law") && e.contains("only contact parts"), "{e}");
    let e = refusal(&t.replace("u = [\"0\", \"-0.01\"]", "u = [\"0\", \"-0.01\"]\ncoulomb = \"0.3\""));
    assert!(e.contains("top") && e.contains("coulomb") && e.contains("only contact parts"), "{e}");
    let e = refusal(
        &t.replace("name = \"left\"\nkind = \"neumann\"", "name = \"left\"\nkind = \"symmetry\"\ng_a = \"0.1\""),
    );
    assert!(e.contains("left") && e.contains("symmetry part takes no keys"), "{e}");
    // a body held only by contact floats (tests/library/floating.rs); frictionless, nothing holds it in x
    let e = refusal(
        &t.replace("kind = \"dirichlet\"\nu = [\"0\", \"-0.01\"]", "kind = \"neumann\"\ntraction = [\"0\", \"-1\"]"),
    );
    assert!(e.contains("the translation in x of the body is not held"), "{e}");
}

/// A unit block with ν = 0 pressed by δ = 0.01 (u₀ is the pressed state, p = Eδ = 2 on Γ_C) and sheared
/// through its top, u_x = 0.01 t; the side tractions ±min(μγt, F p) are those of the uniform state, so
/// the solution is linear (exact for CR): stick while μγt < F p, then slip with σ_xy = F p.
const PRESSED: &str = r#"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [4, 4]
[material]
E = 200.0
nu = 0.0
[[boundary]]
name = "top"
kind = "dirichlet"
u = ["0.01*t", "-0.01"]
[[boundary]]
name = "left"
kind = "neumann"
traction = ["0", "-min(t, 0.6)"]
[[boundary]]
name = "right"
kind = "neumann"
traction = ["0", "min(t, 0.6)"]
[[boundary]]
name = "bottom"
kind = "contact"
law = "unilateral"
FRICTION
[initial]
u0 = ["0", "-0.01*y"]
[time]
T = 1.0
steps = 4
"#;

/// The system shall solve Coulomb friction with a known pressure as Tresca with g_a = F·p: F = 0.3,
/// p = 2, against g_a = 0.6, on a unilateral and on a bilateral part (p the reaction of u·n = 0): the same displacements, friction forces and stick/slip, and the slip of the
/// exact solution, s = γt − F p/μ once it slips. Tolerance: both steps are solved to natural residual
/// ≤ 1e-12 of the force scale (≈ 0.6/4 per edge), so u agrees within 1e-12 of it times cond(C) (< 1e3 for
/// 8 contact unknowns): 1e-9 of max |u|.
#[test]
fn coulomb_with_known_pressure_is_tresca_with_f_times_p() {
    for law in ["law = \"unilateral\"", "law = \"bilateral\""] {
        let scene = |f: &str| {
            let text = PRESSED.replace("law = \"unilateral\"", law).replace("FRICTION", f);
            Scene::from_str(&text, "pressed.toml").unwrap()
        };
        coulomb_equals_tresca(run(scene("coulomb = \"0.3\"")), run(scene("g_a = \"0.6\"")));
    }
}

fn coulomb_equals_tresca(cou: Vec<StepResult>, tre: Vec<StepResult>) {
    let scale = max_abs(tre.iter().flat_map(|r| r.u.iter().copied()));
    for (a, b) in cou.iter().zip(&tre).skip(1) {
        assert!(a.residual <= 1e-12, "step {}: residual {:e}", a.n, a.residual);
        let d = max_abs(a.mu.iter().zip(&b.mu).map(|(x, y)| x - y));
        assert!(d <= 1e-9 * max_abs(b.mu.iter().copied()), "step {}: μ differs by {d:e}", a.n);
        for (j, f) in a.normal.force.iter().enumerate() {
            assert!((f - 2.0 * 0.25).abs() <= 1e-9, "step {}: P_{j} = {f}, want p|e| = 0.5", a.n);
        }
        assert_eq!(a.state, b.state, "step {}", a.n);
        let slip = (0.01 * a.t - 0.3 * 2.0 / 100.0).max(0.0);
        for s in &a.slip {
            assert!((s - slip).abs() <= 1e-9 * scale, "step {}: slip {s:e}, exact {slip:e}", a.n);
        }
    }
    assert_eq!(cou.last().unwrap().n_slip(), 4);
}

/// The system shall say so when Coulomb's semismooth Newton method does not converge (a large F on a
/// block lifting off: the active sets cycle): the run stops naming the step, iterations and residual.
#[test]
fn coulomb_with_a_large_coefficient_that_does_not_converge_says_so() {
    let text = BLOCK
        .replace("TOP", r#"["0.02*t", "-0.01*t + 0.015*t*x"]"#)
        .replace("CONTACT", "law = \"unilateral\"\ncoulomb = \"20\"")
        .replace("nu = 0.3", "nu = 0.0")
        .replace("cells = [8, 8]", "cells = [16, 16]")
        .replace("steps = 4", "steps = 3");
    let e = refusal(&text);
    for n in ["step 1", "coulomb ssn", "did not converge", "iterations", "residual"] {
        assert!(e.contains(n), "message `{e}` lacks `{n}`");
    }
}

/// The system shall assemble a contact part's `traction` as a surface load on Γ_C besides the contact
/// reaction: a block lifted off its foundation (every Γ_C edge separated, no friction) with the traction
/// on its unilateral part is the block whose bottom is a Neumann part with that traction. Tolerance: the
/// natural residual ≤ 1e-12 of the force scale leaves the normal forces at zero up to it times cond(C)
/// (< 1e3): 1e-9 of max |u|.
#[test]
fn contact_traction_is_a_surface_load_on_gamma_c() {
    let top = r#"["0", "0.01*t"]"#;
    let traction = "traction = [\"0.1*t\", \"-0.05*t\"]";
    let con = common::run(block(top, &format!("law = \"unilateral\"\ng_a = \"0\"\n{traction}")));
    let text =
        BLOCK.replace("TOP", top).replace("kind = \"contact\"\nCONTACT", &format!("kind = \"neumann\"\n{traction}"));
    let neu = common::run(Scene::from_str(&text, "n.toml").unwrap());
    let last = con.1.last().unwrap();
    assert!(last.normal.separated.iter().all(|&s| s), "{:?}", last.normal.separated);
    let (a, b) = (con.0.displacement(&last.u, last.t).unwrap(), {
        let r = neu.1.last().unwrap();
        neu.0.displacement(&r.u, r.t).unwrap()
    });
    let scale = max_abs(b.iter().flatten().copied());
    let d = max_abs(a.iter().zip(&b).flat_map(|(x, y)| [x[0] - y[0], x[1] - y[1]]));
    assert!(d <= 1e-9 * scale, "|u_contact - u_neumann| = {d:e} (max |u| {scale:e})");
}

/// The system shall mark a unilateral edge separated at step 0 by the rule of the later steps: open by
/// more than 1e-9 of the scale max_e max(|u⁰·n|, |ḡ_e|) (here 1e-3): u⁰·n = −1e-3 on Γ_C, so a gap
/// −1e-3 + 1e-13 x leaves a rounding-sized opening (≤ 1e-13 < 1e-12): closed; −1e-3 + 1e-6 x opens every
/// edge (x ≥ 1/16) by ≥ 6e-8 > 1e-12: separated. A bilateral edge is never separated.
#[test]
fn step_zero_separation_has_the_later_steps_tolerance() {
    let at_start = |contact: &str| {
        let text = BLOCK
            .replace("TOP", r#"["0", "-0.01*t"]"#)
            .replace("CONTACT", contact)
            .replace("[time]", "[initial]\nu0 = [\"0\", \"0.001*(1 - y)\"]\n[time]");
        let s = Scene::from_str(&text, "block.toml").unwrap_or_else(|e| panic!("{e}"));
        run(s)[0].normal.separated.clone()
    };
    let closed = at_start("law = \"unilateral\"\ngap = \"-0.001 + 1e-13*x\"\ng_a = \"0.05\"");
    assert!(!closed.is_empty() && closed.iter().all(|&s| !s), "rounding marked separated: {closed:?}");
    let open = at_start("law = \"unilateral\"\ngap = \"-0.001 + 1e-6*x\"\ng_a = \"0.05\"");
    assert!(open.iter().all(|&s| s), "an open gap not marked separated: {open:?}");
    let bilateral = at_start("coulomb = \"0.3\"\ngap = \"-0.001 + 1e-6*x\"");
    assert!(bilateral.iter().all(|&s| !s), "a bilateral edge marked separated: {bilateral:?}");
}

/// Largest Newton steps a step may take at a refine level beyond those it takes at refine 0, where the
/// fronts of the start are off by more edges on finer meshes. The active-set methods move a contact or
/// stick/slip front by about one Γ_C edge per Newton step; the nested-iteration predictor
/// (`friction::nested`) starts the fine level from the sets of the level twice as coarse, whose groups
/// of two edges straddling a front take one side's set, so its fronts are within two edges of the fine
/// ones: two steps to move them and one that checks. The predecessors (the plain Hüeber–Stadler–Wohlmuth
/// iteration and the projected Newton method) exceed it: their count grows with the edges a front moves.
const MESH_STEPS: usize = 3;

/// The largest iteration count of the steps of `case` (solved to its tolerance: residual ≤ 1e-12) at
/// refine 0..=4, with `steps` of them counted (`skip` the initial state and any more).
fn iterations_per_level(case: &str, refine_line: &str, skip: usize) -> Vec<usize> {
    let text = std::fs::read_to_string(common::root(&format!("verification/cases/{case}"))).unwrap();
    assert!(text.contains(refine_line), "{case}: its refine line is not where this test expects it");
    (0..=4)
        .map(|k| {
            let s = Scene::from_str(&text.replace(refine_line, &format!("refine = {k}")), case).unwrap();
            let steps = run(s);
            for r in &steps[1..] {
                assert!(r.residual <= 1e-12, "{case} refine {k} step {}: residual {:e}", r.n, r.residual);
            }
            steps.iter().skip(skip).map(|r| r.iterations).max().unwrap()
        })
        .collect()
}

/// The system shall solve the Coulomb block (verification/cases/coulomb_block.toml: pressed and sheared
/// at once, proportionally) at refine 0..4 with per-step Newton iterations that do not grow with the mesh:
/// every step after the first is solved to the tolerance in at most as many iterations at refine 4 as at
/// refine 0. The bound is exact, not fitted: under proportional loading each step's active sets are the
/// previous step's, and the first Newton step of a step takes the sets of its warm start (that previous
/// solution, `friction::coulomb`), so it lands on the solution and the next iteration only checks it,
/// at every h. The first step starts from λ = 0, from the predicted sets (`friction::nested`): at most
/// [`MESH_STEPS`] more than at refine 0.
#[test]
fn coulomb_block_iterations_do_not_grow_with_the_mesh() {
    let later = iterations_per_level("coulomb_block.toml", "refine   = 2", 2);
    assert!(later.iter().all(|&m| m <= later[0]), "max iterations of steps 2.. per refine: {later:?}");
    let all = iterations_per_level("coulomb_block.toml", "refine   = 2", 1);
    assert!(all.iter().all(|&m| m <= all[0] + MESH_STEPS), "max iterations of steps 1.. per refine: {all:?}");
}

/// The system shall solve unilateral Tresca contact whose contact/separation and stick/slip points move
/// along Γ_C (verification/cases/mms_signorini_moving.toml, 8 steps: a point moves 2.5 % and 5 % of Γ_C a
/// step, twice as many edges at each refine) at refine 0..4 in a number of Newton steps per step that
/// does not grow with the mesh: at most [`MESH_STEPS`] more than at refine 0, step 1 (from λ = 0)
/// included.
#[test]
fn moving_fronts_iterations_do_not_grow_with_the_mesh() {
    let all = iterations_per_level("mms_signorini_moving.toml", "refine   = 0", 1);
    assert!(all.iter().all(|&m| m <= all[0] + MESH_STEPS), "max iterations of steps 1.. per refine: {all:?}");
}

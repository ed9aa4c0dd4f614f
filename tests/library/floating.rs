//! Requirements of issue 40's floating bodies: a body held only by contact and symmetry parts (no
//! Dirichlet part) is solved exactly, and loads that contact cannot balance are refused naming the step
//! and the rigid motion (`solve::kernel`, `friction::floating`).

use crate::common;
use common::*;
use tresca_cr::{Error, Problem, Scene, StepResult};

/// A unit block on the foundation `floor`, sides `left` and `right`, top `top` and body force `f`.
fn block(floor: &str, left: &str, top: &str, f: &str, steps: usize) -> String {
    format!(
        "[mesh]\ncorners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]\ncells = [4, 4]\n\
         [material]\nE = 10.0\nnu = 0.3\n\
         [[boundary]]\nname = \"bottom\"\n{floor}\n\
         [[boundary]]\nname = \"left\"\n{left}\n\
         [[boundary]]\nname = \"right\"\nkind = \"neumann\"\ntraction = [\"0\", \"0\"]\n\
         [[boundary]]\nname = \"top\"\n{top}\n\
         [loads]\nf = {f}\n[time]\nT = 1.0\nsteps = {steps}\n"
    )
}

/// Every step of a scene, and the error that stopped it (if any).
fn run_all(text: &str) -> (Vec<StepResult>, Option<Error>) {
    let p = Problem::new(Scene::from_str(text, "floating.toml").unwrap()).unwrap();
    let mut out = Vec::new();
    let e = p
        .run(tresca_cr::RunOptions::all(), |r| {
            out.push(r.clone());
            Ok(())
        })
        .err();
    (out, e)
}

/// The system shall solve the floating block of verification/cases/floating_block.toml (frictionless
/// unilateral foundation, symmetry plane, uniform pressure on top; three rigid motions held only by
/// contact) exactly: its solution is linear, so CR's error is the solver's alone. The solver stops at
/// natural residual 1e-12 relative to the forces; with K's condition (~1e3 on this mesh) the errors are
/// then ≤ 1e-9 (they are 1e-13 measured), where any penalty, spring or unbalanced rigid motion
/// (errors ~1e-2 and above) fails. The contact pressure is p = t on every Γ_C edge.
#[test]
fn floating_block_is_exact() {
    let (p, steps) = run(scene("verification/cases/floating_block.toml"));
    let (energy, l2) = max_errors(&steps);
    assert!(energy <= 1e-9 && l2 <= 1e-9, "energy {energy:e}, L2 {l2:e}");
    let last = steps.last().unwrap();
    assert_eq!(last.rigid.len(), 3, "two translations and the rotation float");
    for (c, &force) in p.space.contact.iter().zip(&last.normal.force) {
        // P_e = |e| p = 0.25 t at t = 1 on the foundation, 0 on the symmetry plane (σ_xx = 0)
        let want = if c.unilateral { 0.25 } else { 0.0 };
        assert!((force - want).abs() <= 1e-9, "{force} {:?}", last.normal);
    }
}

/// The system shall solve a floating block pressed (p = 1) and sheared (τ = 0.4 t) on a unilateral
/// Coulomb foundation (F = 0.5), with no Dirichlet part and no symmetry part, exactly: with ν = 0 and the
/// side tractions of the uniform state σ = [[0, τ], [τ, −p]] the solution is linear,
/// u = (τ y / μ, −p y / E) (E = 10, μ = 5), sticking everywhere since τ < F p (friction holds the
/// translation in x, the pressure the translation in y and the rotation). The tolerance is the solver's
/// (1e-12 on the forces) times K's condition (~1e3): ≤ 1e-9.
#[test]
fn pressed_and_sheared_coulomb_block_floats_exactly() {
    let text = block(
        "kind = \"contact\"\nlaw = \"unilateral\"\ncoulomb = \"0.5\"",
        "kind = \"neumann\"\ntraction = [\"0\", \"-0.4*t\"]",
        "kind = \"neumann\"\ntraction = [\"0.4*t\", \"-1\"]",
        "[\"0\", \"0\"]",
        4,
    )
    .replace("nu = 0.3", "nu = 0.0")
    .replace(
        "name = \"right\"\nkind = \"neumann\"\ntraction = [\"0\", \"0\"]",
        "name = \"right\"\nkind = \"neumann\"\ntraction = [\"0\", \"0.4*t\"]",
    ) + "[exact]\nu = [\"0.08*t*y\", \"-0.1*y\"]\ngrad = [[\"0\", \"0.08*t\"], [\"0\", \"-0.1\"]]\n";
    let (steps, e) = run_all(&text);
    assert!(e.is_none(), "{e:?}");
    let (energy, l2) = max_errors(&steps[1..]);
    assert!(energy <= 1e-9 && l2 <= 1e-9, "energy {energy:e}, L2 {l2:e}");
    let last = steps.last().unwrap();
    assert_eq!(last.rigid.len(), 3);
    assert!(last.state.iter().all(|s| *s == tresca_cr::friction::EdgeState::Stick));
}

/// The system shall refuse a step whose loads the contact forces cannot balance, naming the step and the
/// rigid motion, after handing out the steps before it: a block on a Tresca foundation (bound 0.5 per
/// unit length) pushed sideways by a body force 0.9 t, beyond the bound from t = 5/8 on (step 5 of 8); and a block
/// tipped over by a shear on its top.
#[test]
fn unbalanced_loads_are_refused_naming_step_and_motion() {
    let neumann = "kind = \"neumann\"\ntraction = [\"0\", \"0\"]";
    let text = block(
        "kind = \"contact\"\nlaw = \"unilateral\"\ng_a = \"0.5\"",
        "kind = \"symmetry\"",
        "kind = \"neumann\"\ntraction = [\"0\", \"-1\"]",
        "[\"0.9*t\", \"0\"]",
        8,
    );
    // the symmetry plane holds x: move it to the top so that x is free
    let text = text.replace("name = \"left\"\nkind = \"symmetry\"", &format!("name = \"left\"\n{neumann}"));
    let (steps, e) = run_all(&text);
    assert_eq!(steps.len(), 5, "steps 0..4 completed");
    let e = e.expect("refused").to_string();
    assert!(
        e.starts_with("step 5 (t = 0.625)") && e.contains("along the translation in x") && e.contains("cannot balance"),
        "{e}"
    );
    // a net moment: the same block tipped by a shear on its top that the floor cannot hold upright
    let tipped = block(
        "kind = \"contact\"\nlaw = \"unilateral\"\ng_a = \"5\"",
        neumann,
        "kind = \"neumann\"\ntraction = [\"0.5*t\", \"-1\"]",
        "[\"0\", \"0\"]",
        2,
    );
    let (steps, e) = run_all(&tipped);
    let e = e.expect("refused").to_string();
    assert!(steps.len() == 2 && e.starts_with("step 2") && e.contains("the rotation about (8.75"), "{e}");
}

/// u = K⁺(l − Eλ) + Rα of the floating Coulomb block at t = 1 (one step from u₀ = 0), with the rigid
/// motions pinned at `pinned` (K⁺ from K_#'s factor, `solve::kernel`).
fn solved_with_pinning(pinned: Option<Vec<usize>>) -> Vec<f64> {
    use tresca_cr::solve::{cholesky::Factor, kernel::Kernel};
    let text = block(
        "kind = \"contact\"\nlaw = \"unilateral\"\ncoulomb = \"0.5\"",
        "kind = \"neumann\"\ntraction = [\"0\", \"0\"]",
        "kind = \"neumann\"\ntraction = [\"0.2*(1 - x)\", \"-1\"]",
        "[\"0\", \"-0.5*x\"]",
        1,
    );
    let scene = Scene::from_str(&text, "pinned.toml").unwrap();
    let p = Problem::new(scene.clone()).unwrap();
    let (mesh, space) = (&p.mesh, &p.space);
    let mut kernel = Kernel::of(mesh, space).expect("floating");
    if let Some(pinned) = pinned {
        kernel.pinned = pinned;
    }
    let factor = Factor::new(&kernel.pin(&p.stiffness)).unwrap();
    let kplus = |b: &[f64]| {
        let mut x = b.to_vec();
        factor.solve_in_place(&mut x);
        kernel.complete(&mut x, &[]);
        x
    };
    let dofs = space.contact_dofs();
    let n = space.n_dofs;
    let mut c = nalgebra::DMatrix::zeros(dofs.len(), dofs.len());
    for (j, &dj) in dofs.iter().enumerate() {
        let mut b = vec![0.0; n];
        b[dj] = 1.0;
        let x = kplus(&b);
        for (i, &di) in dofs.iter().enumerate() {
            c[(i, j)] = x[di];
        }
    }
    let c = 0.5 * (&c + c.transpose());
    let mut l = Vec::new();
    tresca_cr::fem::loads::Loads::new(&scene, mesh, space, None).unwrap().assemble(1.0, &mut l).unwrap();
    let uf = kplus(&l);
    let d: Vec<f64> = dofs.iter().map(|&k| uf[k]).collect(); // s_old = 0, gap 0
    let friction = tresca_cr::friction::Friction::new(&scene, mesh, space, c)
        .unwrap()
        .with_floating(kernel.rows(&dofs), kernel.motions.clone());
    let sol = friction.solve_rigid(&d, (&vec![0.0; dofs.len()], &[]), &kernel.net_full(&l), 1, 1.0).unwrap();
    let lam: Vec<f64> = sol.mu.iter().chain(&sol.normal).copied().collect();
    let mut rhs = l.clone();
    dofs.iter().zip(&lam).for_each(|(&k, v)| rhs[k] -= v);
    let mut u = kplus(&rhs);
    kernel.complete(&mut u, &sol.rigid);
    u
}

/// The system shall give a floating body the same displacement whichever unknowns pin its rigid motions
/// (the rigid part Rα of the solution is fixed by the contact forces, not by the pinning): two pinnings
/// of the pressed, unevenly loaded Coulomb block agree to the solver's tolerance (1e-12 on the forces)
/// times K_#'s condition (~1e3), ≤ 1e-8 relative, where a pinning that leaked into the answer would
/// move u by the size of the rigid motion (order 1 relative).
#[test]
fn results_do_not_depend_on_the_pinned_unknowns() {
    let a = solved_with_pinning(None);
    // three other unknowns off Γ_C that block the rigid motions: both components of the first free edge
    // and the x component of the last one
    let kernel_default = {
        let text = block(
            "kind = \"contact\"\nlaw = \"unilateral\"\ncoulomb = \"0.5\"",
            "kind = \"neumann\"\ntraction = [\"0\", \"0\"]",
            "kind = \"neumann\"\ntraction = [\"0\", \"0\"]",
            "[\"0\", \"0\"]",
            1,
        );
        let p = Problem::new(Scene::from_str(&text, "k.toml").unwrap()).unwrap();
        let k = tresca_cr::solve::kernel::Kernel::of(&p.mesh, &p.space).unwrap();
        let contact = p.space.contact_dofs();
        let free: Vec<usize> = (0..p.space.n_dofs).filter(|d| !contact.contains(d)).collect();
        (k.pinned.clone(), free)
    };
    let (default, free) = kernel_default;
    let other = vec![free[0], free[1], free[free.len() - 2]];
    assert_ne!(default, other, "the other pinning differs");
    let b = solved_with_pinning(Some(other));
    let d = rel_diff(&a, &b);
    assert!(d <= 1e-8, "{d:e}");
    assert!(a.iter().any(|v| v.abs() > 1e-3), "a nonzero displacement");
}

/// The system shall resume a floating-body run bit-identically: a run of each floating block of
/// verification/cases (frictionless unilateral with a symmetry plane; Coulomb with none) stopped after
/// step `stop` and continued with `--resume` (`Writer::resume`) gives a results file equal, bit for bit,
/// to the uninterrupted run's. The floating multiplier iteration (`friction::floating`) is warm-started
/// from the previous step's rigid motion α, so α must come back from the file exactly.
#[test]
fn resume_of_a_floating_body_is_bit_identical() {
    use tresca_cr::output::{Run, Writer};
    for (case, steps, stop) in [("floating_block", 6, 3), ("floating_coulomb_block", 8, 4)] {
        let mut s = scene(&format!("verification/cases/{case}.toml"));
        s.set_steps(steps).unwrap();
        let p = Problem::new(s).unwrap();
        let full = tmp_in("tresca-floating", &format!("{case}_full.h5"));
        let part = tmp_in("tresca-floating", &format!("{case}_part.h5"));
        let mut w = Writer::create(&full, &Run::of(&p), true).unwrap();
        p.run(tresca_cr::RunOptions::all(), |r| w.write_step(r)).unwrap();
        w.finish("completed").unwrap();
        {
            let mut w = Writer::create(&part, &Run::of(&p), true).unwrap();
            let stopped = p.run(tresca_cr::RunOptions::all(), |r| {
                if r.n > stop {
                    return Err(Error::Linear("stopped".into()));
                }
                w.write_step(r)
            });
            assert!(stopped.is_err(), "{case}: the run was not stopped");
            // dropped without finish: as after a kill between steps
        }
        let (mut w, last) = Writer::resume(&part, &Run::of(&p)).unwrap();
        let last = last.expect("a committed step");
        assert_eq!((last.n, w.completed()), (stop, stop + 1), "{case}");
        p.run(tresca_cr::RunOptions::after(last), |r| w.write_step(r)).unwrap();
        w.finish("completed").unwrap();
        same_results(&full, &part);
    }
}

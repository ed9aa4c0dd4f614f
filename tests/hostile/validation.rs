//! Hostile inputs of issue 43 §2, §3 and §7: one validation for every command (boundary data that do not
//! fit together are refused by `check`, `run`, `--resume`, `study`, `plan` and `adapt` alike, before
//! any work), scene arrays that were cut, data cancelling by rounding, friction bounds the audit cannot
//! multiply, and messages that blamed the wrong cause.

use super::{run, s, stderr, tmp};
use tresca_cr::Scene;

/// A unit square: Dirichlet `left` and `bottom` with data, the others traction free (no contact, so the
/// studies and plans below are quick); `extra` is appended, `bottom_u` is the bottom part's u[0].
fn two_dirichlet(bottom_u: &str, steps: usize, extra: &str) -> String {
    format!(
        r#"
[mesh]
corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
cells = [2, 2]
[material]
E = 10.0
nu = 0.3
[[boundary]]
name = "left"
kind = "dirichlet"
u = ["0.01*t", "0"]
[[boundary]]
name = "bottom"
kind = "dirichlet"
u = ["{bottom_u}", "0"]
[[boundary]]
name = "right"
kind = "neumann"
traction = ["0.001*t", "0"]
[[boundary]]
name = "top"
kind = "neumann"
[time]
T = 1.0
steps = {steps}
{extra}
"#
    )
}

fn write(name: &str, text: &str) -> String {
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// §2: the system shall refuse, in every command and before any level, pilot or step is run, boundary
/// data that do not fit together: u₀ against u_D(t₀), and two Dirichlet parts that disagree at their
/// common vertex late in time only (t > 0.5), naming the cause.
#[test]
fn every_command_validates_the_boundary_data() {
    let u0 = write("u0.toml", &two_dirichlet("0.01*t", 4, "[initial]\nu0 = [\"0.001\", \"0\"]"));
    let late = write("late.toml", &two_dirichlet("0.01*t + 0.0005*(t - 0.5 + abs(t - 0.5))", 4, ""));
    let out = tmp("validated.h5");
    for (scene, want) in [(&u0, "initial.u0"), (&late, "common vertex")] {
        for args in [
            vec!["check", scene.as_str()],
            vec!["run", scene, "-q"],
            vec!["run", scene, "-q", "-o", s(&out), "--resume"],
            vec!["study", scene, "--levels", "0:4,1:8"],
            vec!["plan", scene, "--target", "1e-3", "--uniform-only"],
            vec!["adapt", scene, "--levels", "2"],
        ] {
            let o = run(&args);
            assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
            let e = stderr(&o);
            assert!(e.contains("inconsistent boundary data") && e.contains(want), "{args:?}: {e}");
            assert!(o.stdout.is_empty(), "{args:?}: work was done: {}", String::from_utf8_lossy(&o.stdout));
        }
    }
    assert!(!out.exists());
}

/// §2: the system shall check the data at the time nodes of every level of a study, also of a level
/// that shares another level's mesh set-up: data that disagree at t = 0.75 only are accepted on the
/// grid {0, 1} and refused on {0, 0.25, 0.5, 0.75, 1}.
#[test]
fn a_shared_set_up_checks_each_time_grid() {
    let mid = "0.01*t + 0.0005*(0.25 - abs(t - 0.75) + abs(0.25 - abs(t - 0.75)))";
    let one = Scene::from_str(&two_dirichlet(mid, 1, ""), "one").unwrap();
    let four = Scene::from_str(&two_dirichlet(mid, 4, ""), "four").unwrap();
    let shared = tresca_cr::stepping::MeshSetUp::new(&one, tresca_cr::stepping::Guard::Estimate).unwrap();
    assert!(tresca_cr::Problem::on_shared(one, &shared).is_ok());
    let e = tresca_cr::Problem::on_shared(four, &shared).err().expect("refused").to_string();
    assert!(e.contains("inconsistent boundary data") && e.contains("t = 0.75"), "{e}");
    let scene = write("mid.toml", &two_dirichlet(mid, 1, ""));
    let o = run(&["study", &scene, "--levels", "0:1,0:4"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("inconsistent boundary data"), "{}", stderr(&o));
}

/// §2: the system shall refuse `u = [a, b, c]` on a Dirichlet part (it dropped the third component),
/// as it refuses three cells, corners or traction components.
#[test]
fn dirichlet_data_with_three_components_are_refused() {
    let text = two_dirichlet("0.01*t", 4, "").replace(r#"u = ["0.01*t", "0"]"#, r#"u = ["0.01*t", "0", "1"]"#);
    let e = Scene::from_str(&text, "three.toml").map(|_| ()).expect_err("refused").to_string();
    assert!(e.contains("expected 2 values, found 3"), "{e}");
}

/// The mesh, space and scene of a unit square with a contact part `bottom` whose `gap` is `gap`.
fn with_gap(gap: &str) -> (Scene, tresca_cr::mesh::Mesh, tresca_cr::fem::space::CrSpace) {
    let text = two_dirichlet("0", 2, "").replace(
        "kind = \"dirichlet\"\nu = [\"0\", \"0\"]",
        &format!("kind = \"contact\"\ng_a = \"0.1\"\ngap = \"{gap}\""),
    );
    let scene = Scene::from_str(&text.replace(r#"u = ["0.01*t", "0"]"#, ""), "gap.toml").unwrap();
    let mesh = tresca_cr::mesh::Mesh::from_spec(&scene.mesh).unwrap();
    let space = tresca_cr::fem::space::CrSpace::new(&mesh, &scene.parts).unwrap();
    (scene, mesh, space)
}

/// §2: the system shall accept data that cancel to zero at t₀ by rounding (the example of
/// src/fem/lifting/consistency.rs's doc: 1.7e-18 at t = 0, once refused with a tolerance of 1e-27),
/// within the rounding bound of the expression, and refuse a real mismatch of 1e-17 with u₀·n = 0.
#[test]
fn data_cancelling_by_rounding_are_accepted() {
    use tresca_cr::fem::lifting::consistency::check;
    let cancel = "(0.1 + t)^2 - 0.01 - 0.2*t - t^2";
    let e = tresca_cr::scene::expr::Expr::parse("gap", cancel).unwrap();
    let (v, r) = (e.eval(0.3, 0.0, 0.0).unwrap(), e.rounding(0.3, 0.0, 0.0));
    assert!(v != 0.0 && v.abs() <= r && r < 1e-16, "value {v:e}, bound {r:e}");
    let (scene, mesh, space) = with_gap(cancel);
    check(&scene, &mesh, &space).unwrap();
    let (scene, mesh, space) = with_gap("1e-17");
    let e = check(&scene, &mesh, &space).expect_err("refused").to_string();
    assert!(e.contains("inconsistent boundary data") && e.contains("gap"), "{e}");
}

/// §3: the system shall refuse a friction bound whose force on an edge, |e|·ḡ_e, the friction solver and
/// the energy audit cannot multiply (g_a = 1e308 ran with exit 0 and an audit of inf and NaN), in every
/// command, naming the part; g_a = 1e150 (|e|ḡ = 2e150, within √(1.8e308)) still runs.
#[test]
fn friction_bounds_the_audit_cannot_multiply_are_refused() {
    let huge = super::scene_with("g_a_huge.toml", "g_a = \"0.0012\"", "g_a = \"1e308\"");
    for args in [vec!["check", huge.as_str()], vec!["run", &huge, "-q", "--steps", "4"]] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("(bottom).g_a") && e.contains("friction force"), "{args:?}: {e}");
    }
    let large = super::scene_with("g_a_large.toml", "g_a = \"0.0012\"", "g_a = \"1e150\"");
    let out = tmp("g_a_large.h5");
    let o = run(&["run", &large, "-q", "--steps", "4", "-o", s(&out), "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let f = hdf5::File::open(&out).unwrap();
    for k in tresca_cr::output::tresca::AUDIT {
        let v: Vec<f64> = f.dataset(&format!("tresca/steps/{k}")).unwrap().read_raw().unwrap();
        assert!(v.iter().all(|x| x.is_finite()), "{k}: {v:?}");
    }
}

/// §7: the system shall blame an overflow caused by the boundary data on them, by part and key, and
/// name only the data the scene gives (not "the loads, u₀ and g_a" of a scene without loads).
#[test]
fn overflow_is_blamed_on_the_data_that_cause_it() {
    let dirichlet = two_dirichlet("1e160*t", 2, "").replace(r#"u = ["0.01*t", "0"]"#, r#"u = ["1e160*t", "0"]"#);
    let dirichlet = dirichlet.replace(r#"traction = ["0.001*t", "0"]"#, "");
    let gap = two_dirichlet("0", 2, "")
        .replace(
            "name = \"left\"\nkind = \"dirichlet\"\nu = [\"0.01*t\", \"0\"]",
            "name = \"left\"\nkind = \"neumann\"",
        )
        .replace(
            "name = \"bottom\"\nkind = \"dirichlet\"\nu = [\"0\", \"0\"]",
            "name = \"bottom\"\nkind = \"contact\"\ng_a = \"0.1\"\ngap = \"1e160*t\"",
        )
        .replace("name = \"top\"\nkind = \"neumann\"", "name = \"top\"\nkind = \"dirichlet\"")
        .replace(r#"traction = ["0.001*t", "0"]"#, "");
    for (name, text, want) in [
        ("u_overflows.toml", dirichlet, "part `left`'s u and part `bottom`'s u"),
        ("gap_overflows.toml", gap, "part `bottom`'s gap"),
    ] {
        let p = write(name, &text);
        let o = run(&["run", &p, "-q"]);
        assert_eq!(o.status.code(), Some(1), "{name}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("overflows") && e.contains(want), "{name}: {e}");
        assert!(!e.contains("the loads") && !e.contains("u₀"), "{name}: {e}");
    }
}

/// §7: the system shall print a memory limit in a unit that shows it (`--max-memory 10M` was "0.0 GB"
/// in plan's refusal) and refuse a mesh whose counts exceed 64 bits without wrapped sizes
/// (`cells = [2^32, 2^32]` reported "18446744073709551615 triangles").
#[test]
fn sizes_are_printed_as_they_are() {
    let ex = super::root("verification/cases/paper_example_5_1.toml");
    let o = run(&["plan", &ex, "--target", "1e-3", "--max-memory", "10M"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("10.0 MB") && !out.contains("0.0 GB"), "{out}{}", stderr(&o));
    let cells = super::scene_with("cells_2_32.toml", "cells = [2, 2]", "cells = [4294967296, 4294967296]");
    for args in [vec!["check", cells.as_str()], vec!["run", &cells, "-q"], vec!["study", &cells, "--levels", "0:4,1:8"]]
    {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains("3.689e19 triangles") && !e.contains("18446744073709551"), "{args:?}: {e}");
    }
}

//! Bad input never panics or lies: every invalid scene, mesh or expression gives an error naming the
//! problem (and the key, line or location), checked here message by message.

use crate::common;

use tresca_cr::{Problem, Scene};

const BASE: &str = r#"
[mesh]
corners = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]
cells = [2, 2]
[material]
E = 200.0
nu = 0.3
[[boundary]]
name = "right"
kind = "dirichlet"
[[boundary]]
name = "left"
kind = "neumann"
traction = ["0.02*(5-y)*t", "-0.01*t"]
[[boundary]]
name = "top"
kind = "neumann"
[[boundary]]
name = "bottom"
kind = "contact"
g_a = "0.0012"
[time]
T = 1.0
steps = 4
"#;

/// The error (scene parse or set-up) of a modified base scene.
fn error_of(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "base scene lacks `{from}`");
    let text = BASE.replacen(from, to, 1);
    match Scene::from_str(&text, "bad.toml") {
        Err(e) => e.to_string(),
        Ok(s) => match Problem::new(s) {
            Err(e) => e.to_string(),
            Ok(p) => p
                .run(tresca_cr::RunOptions::all(), |_| Ok(()))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_else(|| panic!("`{to}` was accepted")),
        },
    }
}

fn expect(from: &str, to: &str, needles: &[&str]) {
    let e = error_of(from, to);
    for n in needles {
        assert!(e.contains(n), "replacing `{from}` by `{to}`: message `{e}` lacks `{n}`");
    }
}

#[test]
fn base_scene_is_valid() {
    let s = Scene::from_str(BASE, "base.toml").unwrap();
    Problem::new(s).unwrap().run(tresca_cr::RunOptions::all(), |_| Ok(())).unwrap();
}

#[test]
fn material_out_of_range() {
    expect("E = 200.0", "E = -1.0", &["bad.toml", "material.E", "positive"]);
    expect("E = 200.0", "E = 0.0", &["material.E"]);
    expect("nu = 0.3", "nu = 0.5", &["material.nu", "0.5"]);
    expect("nu = 0.3", "nu = -1.0", &["material.nu"]);
    expect("nu = 0.3", "nu = nan", &["material.nu"]);
}

#[test]
fn boundary_parts() {
    expect(
        "name = \"top\"\nkind = \"neumann\"",
        "name = \"lid\"\nkind = \"neumann\"",
        &["boundary part `top` of the mesh is not declared in the scene"],
    );
    expect("name = \"top\"\nkind = \"neumann\"", "name = \"right\"\nkind = \"neumann\"", &["right", "named twice"]);
    expect(
        "name = \"right\"\nkind = \"dirichlet\"",
        "name = \"right\"\nkind = \"neumann\"",
        // a floating body (issue 40) whose side load its bilateral Tresca foundation cannot hold
        &["step 1", "along the translation in x", "rigid motion", "add a dirichlet part"],
    );
    expect("kind = \"contact\"", "kind = \"friction\"", &["line", "unknown variant"]);
    expect("g_a = \"0.0012\"", "g_a = \"-0.1\"", &["g_a", ">= 0"]);
    expect("g_a = \"0.0012\"", "g_a = \"0.1*(x - 2)\"", &["g_a", "negative friction bound"]);
    expect("g_a = \"0.0012\"", "g_a = \"0.1*t\"", &["g_a", "must not depend on t"]);
    expect("g_a = \"0.0012\"", "", &["contact part needs g_a"]);
    expect("traction = [\"0.02*(5-y)*t\", \"-0.01*t\"]", "traction = [\"1\"]", &["line"]);
}

#[test]
fn expressions() {
    expect("-0.01*t", "-0.01*z", &["unknown variable `z`", "traction"]);
    expect("-0.01*t", "1/(x - 0)", &["traction", "value inf"]);
    expect("-0.01*t", "sqrt(0 - 1 - t)", &["traction", "NaN"]);
    expect("-0.01*t", "-x^2", &["exmex reads"]);
    expect("-0.01*t", "(0.01*t", &["cannot parse"]);
    expect("-0.01*t", "", &["empty expression"]);
}

#[test]
fn time_grid() {
    expect("steps = 4", "steps = 0", &["time.steps", "at least 1"]);
    expect("T = 1.0", "T = -1.0", &["time.T", "positive"]);
    expect("T = 1.0", "T = 0.0", &["time.T"]);
    expect("T = 1.0\nsteps = 4", "times = [0.0, 0.5, 0.5, 1.0]", &["time.times", "strictly increasing"]);
    expect("T = 1.0\nsteps = 4", "times = [0.0]", &["time.times", "at least two"]);
    expect("T = 1.0\nsteps = 4", "T = 1.0\nsteps = 4\ntimes = [0.0, 1.0]", &["either"]);
}

#[test]
fn toml_structure() {
    expect("nu = 0.3", "nu = 0.3\nmu = 1.0", &["unknown field `mu`", "line"]);
    expect("E = 200.0", "E = \"200\"", &["line", "invalid type"]);
    expect("cells = [2, 2]", "cells = [2, 0]", &["mesh.cells"]);
    expect("cells = [2, 2]", "cells = [2, 2]\nfile = \"x.msh\"", &["either `file`"]);
    expect("[time]", "[time]\nsteps_per_second = 3", &["unknown field `steps_per_second`"]);
    expect("steps = 4", "steps = 4\n[solver]\nmethod = \"newton\"", &["line", "`newton`: expected ssn, uzawa or pdas"]);
}

#[test]
fn mesh_geometry() {
    expect(
        "[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]",
        "[[0.0, 0.0], [0.0, 4.0], [4.0, 4.0], [4.0, 0.0]]",
        &["counter-clockwise"],
    );
    expect(
        "[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]",
        "[[0.0, 0.0], [4.0, 0.0], [8.0, 0.0], [0.0, 4.0]]",
        &["convex quadrilateral"],
    );
}

#[test]
fn gmsh_files() {
    let dir = common::tmp_in("tresca-validation", "gmsh");
    std::fs::create_dir_all(&dir).unwrap();
    let good = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/verification/cases/lshape.msh")).unwrap();
    let scene = |msh: &str, name: &str| {
        let p = dir.join(name);
        std::fs::write(&p, msh).unwrap();
        let text = format!(
            "[mesh]\nfile = \"{}\"\n[material]\nE = 1.0\nnu = 0.3\n[[boundary]]\nname = \"clamp\"\nkind = \"dirichlet\"\n[[boundary]]\nname = \"loaded\"\nkind = \"neumann\"\n[[boundary]]\nname = \"floor\"\nkind = \"contact\"\ng_a = \"1\"\n[time]\nT = 1.0\nsteps = 1\n",
            p.display()
        );
        Scene::from_str(&text, "msh.toml").and_then(Problem::new).err().map(|e| e.to_string()).unwrap_or_default()
    };
    assert_eq!(scene(&good, "good.msh"), "");
    for cut in [good.len() / 3, good.len() / 2, good.len() - 30] {
        let e = scene(&good[..cut], "trunc.msh");
        assert!(e.contains("trunc.msh") && (e.contains("unexpected end of file") || e.contains("line ")), "{e}");
    }
    assert!(scene("hello", "junk.msh").contains("section header"));
    assert!(scene(&good.replace("4.1 0 8", "2.2 0 8"), "old.msh").contains("need Gmsh 4.1"));
    assert!(
        scene(&good.replace("\"floor\"", "\"ground\""), "renamed.msh").contains("`ground` of the mesh is not declared")
    );
    assert!(scene(&good.replace("\"clamp\"", "\"floor\""), "merged.msh").contains("clamp"));
    let missing = scene(&good.replace("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", ""), "noformat.msh");
    assert!(missing.contains("$MeshFormat"), "{missing}");
    assert!(scene("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", "empty.msh").contains("no 3-node triangles"));
    let nofile = Scene::from_str("[mesh]\nfile = \"/nonexistent/x.msh\"\n[material]\nE = 1.0\nnu = 0.3\n[[boundary]]\nname = \"a\"\nkind = \"dirichlet\"\n[time]\nT = 1.0\nsteps = 1\n", "s.toml")
        .and_then(Problem::new)
        .err()
        .unwrap()
        .to_string();
    assert!(nofile.contains("/nonexistent/x.msh") && nofile.contains("cannot read mesh"), "{nofile}");
}

#[test]
fn solver_failure_is_reported_with_step_iterations_and_residual() {
    // with stick edges (g_a = 0.02) a far too large Uzawa step oscillates between the bounds
    let text = BASE
        .replacen("steps = 4", "steps = 4\n[solver]\nmethod = \"uzawa\"\nuzawa_step = 1e9\nmax_iter = 50", 1)
        .replacen("g_a = \"0.0012\"", "g_a = \"0.02\"", 1);
    let p = Problem::new(Scene::from_str(&text, "s.toml").unwrap()).unwrap();
    let mut completed = 0;
    let e = p
        .run(tresca_cr::RunOptions::all(), |_| {
            completed += 1;
            Ok(())
        })
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("step 1") && e.contains("uzawa did not converge in 50 iterations") && e.contains("residual"),
        "{e}"
    );
    assert_eq!(completed, 1, "step 0 was handed over before the failure");
}

/// The system shall read the deprecated `[outputs]` table and its `energy` key as `[quantities]` and
/// `elastic_energy`, saying so once each, and refuse a scene that gives both spellings.
#[test]
fn deprecated_quantity_names() {
    let new = Scene::from_str(&format!("{BASE}[quantities]\nelastic_energy = true\n"), "q.toml").unwrap();
    assert!(new.deprecations.is_empty(), "{:?}", new.deprecations);
    let old = Scene::from_str(&format!("{BASE}[outputs]\nenergy = true\n"), "o.toml").unwrap();
    assert_eq!(old.outputs, new.outputs);
    assert!(old.outputs.as_ref().is_some_and(|o| o.elastic_energy));
    assert_eq!(old.deprecations.len(), 2, "{:?}", old.deprecations);
    assert!(old.deprecations[0].contains("[outputs] is deprecated: write [quantities]"));
    assert!(old.deprecations[1].contains("energy is deprecated: write elastic_energy"));
    let both = Scene::from_str(&format!("{BASE}[quantities]\nmax_slip = true\n[outputs]\nmax_slip = true\n"), "b.toml");
    assert!(both.err().map(|e| e.to_string()).unwrap_or_default().contains("give [quantities] only"));
    let keys = Scene::from_str(&format!("{BASE}[quantities]\nenergy = true\nelastic_energy = true\n"), "k.toml");
    assert!(keys.err().map(|e| e.to_string()).unwrap_or_default().contains("give elastic_energy only"));
}

//! Faults a hostile user or a flaky machine produces (issue 18), through the release binary where the
//! fault is a process-level one: two runs on one output path, a closed or full standard output, runs that
//! cannot fit, resuming with other settings or over a damaged file, loads at the ends of the f64 range,
//! and the messages of inputs that used to be misreported.

mod common;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use common::{bin, fork_guard, root, spawn, stderr};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("tresca-faults", name)
}

fn run(args: &[&str]) -> Output {
    spawn(bin().args(args)).wait_with_output().unwrap()
}

/// Example 5.1 on the paper's n = 8 mesh (its 2 × 2 cells refined twice) as a scene file of its own,
/// written once per test process.
fn base() -> String {
    static BASE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    BASE.get_or_init(|| {
        let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml")).unwrap();
        assert!(text.contains("cells = [2, 2]"), "paper_example_5_1.toml changed: update base()");
        let p = tmp("base.toml");
        // u0 given explicitly (zero), so that tests can replace it
        let text = text.replace("cells = [2, 2]", "cells = [8, 8]") + "\n[initial]\nu0 = [\"0\", \"0\"]\n";
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    })
    .clone()
}

/// Example 5.1 with `from` replaced by `to`, written to `name`.
fn scene_with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(base()).unwrap();
    assert!(text.contains(from), "{from}");
    let p = tmp(name);
    std::fs::write(&p, text.replace(from, to)).unwrap();
    p.display().to_string()
}

fn long_scene() -> String {
    scene_with(
        "long.toml",
        r#"traction = ["0.02*(5-y)*t", "-0.01*t"]"#,
        r#"traction = ["0.02*(5-y)*sin(3*t*y)", "-0.01*t*cos(t*y)"]"#,
    )
}

fn attr_i64(f: &hdf5::File, group: &str, name: &str) -> i64 {
    f.group(group).unwrap().attr(name).unwrap().read_scalar::<i64>().unwrap()
}

fn status(f: &hdf5::File) -> String {
    f.group("tresca").unwrap().attr("status").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap().to_string()
}

/// A complete, intact results file of `steps` steps, holding exactly one run.
fn assert_complete(path: &Path, steps: i64) {
    let _g = fork_guard();
    let f = hdf5::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(attr_i64(&f, "tresca/steps", "completed"), steps + 1);
    assert_eq!(status(&f), "completed");
    let mut t = tresca_cr::output::tresca::Tresca::open(&f).unwrap();
    assert_eq!(t.first_corrupt_step(steps as usize + 1).unwrap(), None, "checksums of {}", path.display());
}

/// Issue 18.1: two runs started together on one output path. In every trial exactly one succeeds, the
/// other is refused naming the process that holds the path (or the file it left), and a run that
/// reports success has a complete file that it wrote alone; no lock file is left behind.
#[test]
fn two_runs_on_one_path_never_both_succeed() {
    let scene = long_scene();
    let mut outcomes = std::collections::BTreeMap::<String, usize>::new();
    for trial in 0..12 {
        let out = tmp(&format!("cc_{trial}.h5"));
        let args = ["run", &scene, "-o", out.to_str().unwrap(), "-q", "--refine", "2", "--steps", "200"];
        let a = spawn(bin().args(args));
        let b = spawn(bin().args(args));
        let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
        let ok = [a.status.success(), b.status.success()];
        assert!(!(ok[0] && ok[1]), "trial {trial}: both runs reported success");
        assert!(ok[0] || ok[1], "trial {trial}: both runs failed: {} / {}", stderr(&a), stderr(&b));
        for o in [&a, &b].into_iter().filter(|o| !o.status.success()) {
            assert_eq!(o.status.code(), Some(1), "trial {trial}: {}", stderr(o));
            let e = stderr(o);
            let named = e.contains("is already writing this results file") && e.contains("process ");
            assert!(named || e.contains("already exists"), "trial {trial}: {e}");
            *outcomes.entry(if named { "refused: locked" } else { "refused: exists" }.into()).or_default() += 1;
        }
        if ok[0] || ok[1] {
            assert_complete(&out, 200);
        }
        assert!(!tresca_cr::output::lock_path(&out).exists(), "trial {trial}: lock file left behind");
    }
    println!("outcomes of the losers: {outcomes:?}");
    assert!(outcomes.get("refused: locked").copied().unwrap_or(0) >= 1, "the runs never overlapped");
}

/// Issue 18.1: a `--resume` started during a run is refused, with HDF5's own file locking off; the run
/// ends with a complete file.
#[test]
fn resume_during_a_run_is_refused() {
    let scene = long_scene();
    let out = tmp("during.h5");
    let args = ["run", &scene, "-o", out.to_str().unwrap(), "-q", "--refine", "2", "--steps", "600"];
    let mut a = spawn(bin().args(args).env("HDF5_USE_FILE_LOCKING", "FALSE"));
    while !out.exists() && a.try_wait().unwrap().is_none() {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let b = spawn(bin().args(args).arg("--resume").env("HDF5_USE_FILE_LOCKING", "FALSE")).wait_with_output().unwrap();
    let running = a.try_wait().unwrap().is_none();
    assert!(a.wait().unwrap().success());
    if running {
        assert_eq!(b.status.code(), Some(1), "{}", stderr(&b));
        assert!(stderr(&b).contains("is already writing"), "{}", stderr(&b));
    }
    assert_complete(&out, 600);
}

/// Issue 18.4: a closed standard output (`run -v | head -1`) neither panics nor stops the run; the
/// file is complete and the failure is reported. `check > /dev/full` fails with a message, no panic.
#[test]
fn closed_or_full_stdout_is_reported_not_a_panic() {
    let out = tmp("pipe.h5");
    let mut child = spawn(bin().args(["run", &base(), "-v", "-o", out.to_str().unwrap(), "--steps", "400"]));
    drop(child.stdout.take()); // the reader went away
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output could not be written"), "{}", stderr(&o));
    assert_complete(&out, 400);
    if Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = {
            let _g = fork_guard();
            bin().args(["check", &base()]).stdout(full).output().unwrap()
        };
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("cannot write to standard output"), "{}", stderr(&o));
    }
}

/// Issues 18.4 and 18.5: runs that cannot fit are refused before anything is allocated, with the
/// estimate; `check` prints the estimates.
#[test]
fn runs_that_cannot_fit_are_refused_with_the_estimate() {
    for cmd in ["check", "run"] {
        let o = run(&[cmd, &base(), "--steps", "10000000000"]);
        assert_eq!(o.status.code(), Some(1), "{cmd}: {}", stderr(&o));
        assert!(stderr(&o).contains("of memory"), "{cmd}: {}", stderr(&o));
    }
    let huge = scene_with("huge.toml", "cells = [8, 8]", "cells = [10000, 10000]");
    for cmd in ["check", "run"] {
        let o = run(&[cmd, &huge, "--max-memory", "16G"]);
        assert_eq!(o.status.code(), Some(1), "{cmd}: {}", stderr(&o));
        assert!(stderr(&o).contains("B of memory") && stderr(&o).contains("--max-memory"), "{}", stderr(&o));
    }
    let out = tmp("big.h5");
    let o = run(&["run", &base(), "--steps", "100000000", "-o", out.to_str().unwrap(), "--max-disk", "1G"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("of disk for the results file"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = run(&["check", &base()]);
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("estimate   memory ~") && text.contains("results file ~"), "{text}");
}

/// Issues 18.3 and 18.6: `--resume` refuses a setting that changes the answer (naming it), says that one
/// which does not is ignored, and refuses a file damaged after it was written, naming the first bad step.
#[test]
fn resume_checks_settings_and_checksums() {
    let out = tmp("res.h5");
    let o = run(&["run", &base(), "-q", "-o", out.to_str().unwrap(), "--steps", "80"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let p = out.to_str().unwrap();
    let o = run(&["run", &base(), "-q", "-o", p, "--steps", "80", "--resume", "--tol", "1e-3"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("tol (--tol"), "{}", stderr(&o));
    let o = run(&["run", &base(), "-q", "-o", p, "--steps", "80", "--resume", "--frame-every", "3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("--frame-every 3 is ignored on --resume"), "{}", stderr(&o));
    assert_complete(&out, 80);
    // 4 kB of noise in row 50 of tresca/u
    let offset = {
        let _g = fork_guard();
        let f = hdf5::File::open(&out).unwrap();
        let ds = f.dataset("tresca/u").unwrap();
        let row = ds.shape()[1] * 2 * 8;
        ds.offset().unwrap() + 50 * row as u64
    };
    let noise: Vec<u8> = (0..4096u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect();
    let f = std::fs::OpenOptions::new().write(true).open(&out).unwrap();
    std::os::unix::fs::FileExt::write_all_at(&f, &noise, offset).unwrap();
    drop(f);
    let o = run(&["run", &base(), "-q", "-o", p, "--steps", "80", "--resume"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("step 50 does not match its checksum"), "{}", stderr(&o));
    let py = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    let _g = fork_guard(); // held while the checker runs: it opens the file with HDF5
    if py.exists() && Command::new(&py).args(["-c", "import vtk, meshio"]).output().is_ok_and(|o| o.status.success()) {
        let o = Command::new(&py).arg(root("scripts/check_results.py")).arg(&out).output().unwrap();
        assert!(!o.status.success());
        // the checker names a damaged file on standard error (one error line, exit 2)
        let text = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        assert!(text.contains("step 50 does not match its checksum"), "{text}");
    }
}

/// Issue 18.2: loads from 1e-300 to 1e300 (traction and g_a together) give u ∝ load to rounding, where
/// the energy a_h(u, u) ~ load² is representable; beyond it the run is refused with a message.
#[test]
fn loads_scale_over_the_f64_range() {
    let text = std::fs::read_to_string(base()).unwrap();
    let scaled = |f: f64| {
        let t = text
            .replace(r#"["0.02*(5-y)*t", "-0.01*t"]"#, &format!(r#"["{f:e}*0.02*(5-y)*t", "-{f:e}*0.01*t"]"#))
            .replace(r#"g_a = "0.0012""#, &format!(r#"g_a = "{f:e}*0.0012""#));
        // a friction force beyond √(f64 range) is refused at the set-up (fem::validate), the energy at its step
        let p = tresca_cr::Problem::new(tresca_cr::Scene::from_str(&t, "scaled.toml").unwrap())?;
        let mut us = Vec::new();
        let r = p.run(tresca_cr::RunOptions::all(), |r| {
            us.push(r.u.clone());
            Ok(())
        });
        r.map(|()| us)
    };
    let one = scaled(1.0).unwrap();
    let scale = one.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    for f in [1e-300, 1e-200, 1e-160, 1e140, 1e150] {
        let u = scaled(f).unwrap_or_else(|e| panic!("load × {f:e}: {e}"));
        let worst = u.iter().flatten().zip(one.iter().flatten()).fold(0.0f64, |a, (x, y)| a.max((x / f - y).abs()));
        assert!(worst <= 1e-12 * scale, "load × {f:e}: max |u/f − u_1| = {worst:e}");
    }
    for f in [1e200, 1e300] {
        let e = scaled(f).expect_err("energy overflows").to_string();
        assert!(e.contains("overflows f64"), "{e}");
    }
    // the issue's case: a huge traction against a unit-size friction bound is frictionless, and says so
    let big = scene_with("t200.toml", r#"["0.02*(5-y)*t", "-0.01*t"]"#, r#"["1e120*t", "-1e120*t"]"#);
    let out = tmp("t200.h5");
    let o = run(&["run", &big, "-q", "-o", out.to_str().unwrap(), "--steps", "4"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o)); // f32 views: |u| ~ 1e118
    assert!(stderr(&o).contains("single-precision range"), "{}", stderr(&o));
    let o = run(&["run", &big, "-q", "--steps", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("treated as zero"), "{}", stderr(&o));
}

/// Issue 18.7: messages that used to mislead, and inputs `check` passed but `run` rejected.
#[test]
fn misleading_messages_are_fixed() {
    // an output path that is a directory is refused before any step
    let dir = tmp("isdir.h5");
    std::fs::create_dir_all(&dir).unwrap();
    let o = run(&["run", &base(), "-q", "-o", dir.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("is a directory") && !stderr(&o).contains("every completed step"), "{}", stderr(&o));
    // the run's own input is never an output
    let scene = scene_with("own.toml", "steps = 40", "steps = 4");
    let before = std::fs::read(&scene).unwrap();
    let o = run(&["run", &scene, "-q", "-o", &scene, "--force"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("overwrite the run's input"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&scene).unwrap(), before);
    // without any output path the run says it keeps nothing
    let o = run(&["run", &scene, "-q"]);
    assert!(o.status.success() && stderr(&o).contains("no results file"), "{}", stderr(&o));
    // what run evaluates before its first step, check evaluates too
    let u0 = scene_with("u0.toml", r#"u0 = ["0", "0"]"#, r#"u0 = ["1/(x-2)", "0"]"#);
    let exact = format!(
        "{}\n[exact]\nu = [\"sqrt(x-1)\", \"0\"]\ngrad = [[\"0\", \"0\"], [\"0\", \"0\"]]\n",
        std::fs::read_to_string(base()).unwrap()
    );
    let exact_path = tmp("exact.toml");
    std::fs::write(&exact_path, exact).unwrap();
    for s in [u0.as_str(), exact_path.to_str().unwrap()] {
        let (c, r) = (run(&["check", s]), run(&["run", s, "-q"]));
        assert_eq!((c.status.code(), r.status.code()), (Some(1), Some(1)), "{s}: {}", stderr(&c));
    }
    // a tiny friction bound against a unit load: frictionless, said so (it used to fail the line search)
    let tiny = scene_with("tiny.toml", r#"g_a = "0.0012""#, r#"g_a = "1e-25""#);
    let o = run(&["run", &tiny, "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("treated as zero"), "{}", stderr(&o));
    // a huge expression is refused at once
    let long = format!("{}x", "x+".repeat(100_000));
    let big = scene_with("bigexpr.toml", r#"g_a = "0.0012""#, &format!(r#"g_a = "{long}""#));
    let start = std::time::Instant::now();
    let o = run(&["check", &big]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("characters is longer than"), "{}", stderr(&o));
    assert!(start.elapsed().as_secs() < 5);
}

/// Issue 18.7: an ill-conditioned K names its likely cause (slivers here, at rho = 10), a mesh of size
/// 1e-150 runs (it used to be called "inverted"), one whose areas leave the normal range is refused
/// saying so, and a piece of the mesh without a Dirichlet edge is found.
#[test]
fn mesh_messages_name_the_cause() {
    let corners = "corners = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]";
    let thin = scene_with("thin.toml", corners, "corners = [[0.0, 0.0], [4e6, 0.0], [4e6, 4.0], [0.0, 4.0]]");
    let o = run(&["check", &thin]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("ill-conditioned") && stderr(&o).contains("aspect ratio up to 1.0e6"),
        "{}",
        stderr(&o)
    );
    assert!(!stderr(&o).contains("Use rho of order 1"), "{}", stderr(&o));
    let small = |f: &str| format!("corners = [[0.0, 0.0], [{f}, 0.0], [{f}, {f}], [0.0, {f}]]");
    let tiny = scene_with("tiny.toml", corners, &small("4e-150"));
    let o = run(&["run", &tiny, "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let tinier = scene_with("tinier.toml", corners, &small("4e-160"));
    let o = run(&["check", &tinier]);
    assert_eq!(o.status.code(), Some(1));
    assert!(
        stderr(&o).contains("beyond the normal range of f64") && !stderr(&o).contains("inverted"),
        "{}",
        stderr(&o)
    );
    // two disjoint squares, only the first clamped: the second floats
    let c = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let a = tresca_cr::mesh::structured_raw(&c, [2, 2], tresca_cr::scene::Diagonal::First).unwrap();
    let c2 = c.map(|p| [p[0] + 5.0, p[1]]);
    let b = tresca_cr::mesh::structured_raw(&c2, [2, 2], tresca_cr::scene::Diagonal::First).unwrap();
    let mut raw = a.clone();
    let np = raw.points.len();
    raw.points.extend(&b.points);
    raw.tris.extend(b.tris.iter().map(|t| t.map(|v| v + np)));
    raw.tagged.extend(b.tagged.iter().map(|&([p, q], tag)| ([p + np, q + np], tag)));
    let mesh = tresca_cr::mesh::Mesh::build(raw).unwrap();
    let left = mesh.tag_names.iter().position(|n| n == "left").unwrap();
    let clamped = |e: usize| mesh.edge_tag[e] == Some(left) && mesh.midpoint(e)[0] < 2.0;
    let p = mesh.floating_piece(clamped).expect("the second square floats");
    assert!(p[0] >= 5.0, "{p:?}");
    assert_eq!(mesh.floating_piece(|e| mesh.edge_tag[e] == Some(left)), None);
}

/// Issue 18.1: a lock file left by a process that died (no `flock` held: the kernel drops the locks of a
/// dead process) does not block the next run, which takes it over and removes it at its end.
#[test]
fn a_stale_lock_is_taken_over() {
    let out = tmp("stale.h5");
    let lock = tresca_cr::output::lock_path(&out);
    std::fs::write(&lock, "4194303 (a run that was killed)").unwrap();
    let o = run(&["run", &base(), "-q", "-o", out.to_str().unwrap(), "--steps", "8"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_complete(&out, 8);
    assert!(!lock.exists());
}

/// Requirement (issue 13, the condition estimate beside the first steps): the solves of K's condition
/// estimate run while the set-up ends and the first steps are computed, but an ill-conditioned K
/// (ρ = 1e-12: plain CR fails Korn's inequality) is still refused before any step is handed out: the
/// library hands no result to the caller, and `run -o` exits 1 naming the cause and writes no results
/// file. A well-conditioned run hands out step 0 first, then every step in order.
#[test]
fn an_ill_conditioned_stiffness_is_refused_before_any_step_is_handed_out() {
    let weak = scene_with("weak.toml", "rho = 10.0", "rho = 1e-12");
    let p = tresca_cr::Problem::new(tresca_cr::Scene::from_file(std::path::Path::new(&weak)).unwrap()).unwrap();
    let mut handed = 0;
    let e = p.run(tresca_cr::RunOptions::all(), |_| {
        handed += 1;
        Ok(())
    });
    assert!(e.as_ref().is_err_and(|e| e.to_string().contains("ill-conditioned")), "{:?}", e.map(|_| ()));
    assert_eq!(handed, 0);
    assert!(p.initial().is_err() && p.conditioned().is_err());
    let out = tmp("weak.h5");
    let o = run(&["run", &weak, "-o", &out.display().to_string(), "-q"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("ill-conditioned") && stderr(&o).contains("rho < 1"), "{}", stderr(&o));
    assert!(!out.exists(), "a results file was written for a refused K");
    let good = tresca_cr::Problem::new(tresca_cr::Scene::from_file(std::path::Path::new(&base())).unwrap()).unwrap();
    let mut steps = Vec::new();
    good.run(tresca_cr::RunOptions::all(), |r| {
        steps.push(r.n);
        Ok(())
    })
    .unwrap();
    assert_eq!(steps, (0..=good.n_steps()).collect::<Vec<_>>());
}

/// Requirement (issue 32, the planner's condition estimate on its first pilot mesh only): the system
/// shall refuse to plan a scene whose K is nearly singular (ρ = 1e-12), exiting 1 with the cause named,
/// although its pilots on other meshes skip the estimate.
#[test]
fn the_planner_refuses_an_ill_conditioned_stiffness() {
    let weak = scene_with("weak_plan.toml", "rho = 10.0", "rho = 1e-12");
    let o = run(&["plan", &weak, "--target", "1e-3"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("ill-conditioned") && stderr(&o).contains("rho < 1"), "{}", stderr(&o));
}

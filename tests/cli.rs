//! The command line end to end (the release binary): determinism of results files, solver failure that
//! keeps completed steps and records why, refused or conflicting output options, and bad input giving a
//! message and exit status 1 — never a panic (exit status 101).

mod common;
use std::path::{Path, PathBuf};
use std::process::Output;

use common::{bin, fork_guard, root, spawn, stderr};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("tresca-cli", name)
}

fn run(args: &[&str]) -> Output {
    spawn(bin().args(args)).wait_with_output().unwrap()
}

fn same_results(a: &Path, b: &Path) {
    let _g = fork_guard();
    common::same_results(a, b);
}

/// The same scene and binary shall give bit-identical results files (wall times aside).
#[test]
fn results_files_are_deterministic() {
    for scene in ["verification/cases/paper_example_5_1.toml", "verification/cases/mms_rotated.toml"] {
        let (a, b) = (tmp("det_a.h5"), tmp("det_b.h5"));
        for out in [&a, &b] {
            let o = run(&[
                "run",
                &root(scene),
                "--refine",
                "1",
                "--steps",
                "12",
                "-q",
                "-o",
                out.to_str().unwrap(),
                "--force",
            ]);
            assert!(o.status.success(), "{}", stderr(&o));
        }
        same_results(&a, &b);
    }
}

/// A non-converging step ends the run with exit status 1 and a message naming step, iterations and
/// residual; the file keeps every completed step and records why the run stopped.
#[test]
fn solver_failure_keeps_completed_steps_and_records_why() {
    let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml"))
        .unwrap()
        .replace("g_a = \"0.0012\"", "g_a = \"0.02\"")
        .replace("method = \"ssn\"", "method = \"uzawa\"\nuzawa_step = 1e9\nmax_iter = 50");
    let scene = tmp("fail.toml");
    std::fs::write(&scene, text).unwrap();
    let out = tmp("fail.h5");
    let o = run(&["run", scene.to_str().unwrap(), "-q", "-o", out.to_str().unwrap(), "--force"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("step 1") && e.contains("did not converge in 50 iterations") && e.contains("residual"), "{e}");
    let _g = fork_guard();
    let f = hdf5::File::open(&out).unwrap();
    let completed = f.group("tresca/steps").unwrap().attr("completed").unwrap().read_scalar::<i64>().unwrap();
    assert_eq!(completed, 1, "step 0 completed, step 1 failed");
    let status =
        f.group("tresca").unwrap().attr("status").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap();
    assert!(status.as_str().contains("did not converge"), "{}", status.as_str());
}

/// The system shall refuse an existing results file (or its sidecar) before it sets the mesh up: from
/// 1,000,000 unknowns the file is created only after the factorisation, so the refusal came after minutes
/// of set-up. Under a 2 GB address-space limit the refine-8 set-up (about 5 GB) cannot run, so only a
/// check made before it gives the refusal; a check made after it fails with an allocation error instead.
#[test]
fn an_existing_output_is_refused_before_the_set_up() {
    let scene = root("verification/cases/paper_example_5_1.toml");
    for (name, planted) in [("big.h5", "big.h5"), ("big_side.h5", "big_side.xdmf")] {
        let out = tmp(name);
        let planted = tmp(planted);
        std::fs::write(&planted, b"not ours").unwrap();
        let cmd = format!(
            "ulimit -v 2000000 && exec '{}' run '{scene}' --refine 8 --steps 4 -o '{}'",
            env!("CARGO_BIN_EXE_tresca-cr"),
            out.display()
        );
        let o = spawn(std::process::Command::new("sh").args(["-c", &cmd])).wait_with_output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        let e = stderr(&o);
        assert!((e.contains("already exists") || e.contains("XDMF file exists")) && e.contains("--force"), "{e}");
        assert_eq!(std::fs::read(&planted).unwrap(), b"not ours");
    }
}

/// Output paths: unwritable → clear error, nothing written; existing → refused and left untouched;
/// --force with --resume → refused by the argument parser; --resume needs a file.
#[test]
fn output_options_are_checked() {
    let scene = root("verification/cases/paper_example_5_1.toml");
    // a path below a regular file can be neither created nor written (missing directories are created)
    let file = tmp("a_file");
    std::fs::write(&file, b"x").unwrap();
    let bad = file.join("x.h5");
    let o = run(&["run", &scene, "-o", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains(bad.to_str().unwrap()), "{}", stderr(&o));
    assert!(!bad.exists());
    let existing = tmp("existing.h5");
    std::fs::write(&existing, b"not a results file").unwrap();
    let o = run(&["run", &scene, "-o", existing.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("already exists") && stderr(&o).contains("--force"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&existing).unwrap(), b"not a results file");
    let o = run(&["run", &scene, "-o", existing.to_str().unwrap(), "--resume"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert_eq!(std::fs::read(&existing).unwrap(), b"not a results file");
    let o = run(&["run", &scene, "-o", existing.to_str().unwrap(), "--force", "--resume"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("cannot be used with"), "{}", stderr(&o));
    let o = run(&["run", &scene, "--resume"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--resume needs a results file"), "{}", stderr(&o));
    let o = run(&["run", &scene, "--steps", "0"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("time.steps"), "{}", stderr(&o));
    // --resume of a file that does not exist is refused, and writes nothing
    let missing = tmp("never_committed.h5");
    let o = run(&["run", &scene, "-o", missing.to_str().unwrap(), "--resume"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("no results file to --resume"), "{}", stderr(&o));
    assert!(!missing.exists());
    // ... unless the run was killed before its first commit (only `.partial` exists): then it starts the
    // same run afresh, and the result equals an uninterrupted run's
    let partial = tmp("never_committed.h5.partial");
    std::fs::write(&partial, b"unfinished").unwrap();
    let o = run(&["run", &scene, "-o", missing.to_str().unwrap(), "--resume", "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(missing.exists() && !partial.exists());
    let full = tmp("uninterrupted.h5");
    assert!(run(&["run", &scene, "-o", full.to_str().unwrap(), "-q"]).status.success());
    same_results(&full, &missing);
}

/// Bad scenes give exit status 1 and a message naming the file — never a panic.
#[test]
fn bad_scenes_fail_cleanly() {
    let cases = [
        ("missing.toml", None, "cannot read scene"),
        ("garbage.toml", Some("this is [not toml"), "garbage.toml"),
        (
            "unknown.toml",
            Some("[mesh]\ncorners = [[0.0,0.0],[1.0,0.0],[1.0,1.0],[0.0,1.0]]\ncells = [1,1]\ncolour = 3\n"),
            "unknown field `colour`",
        ),
    ];
    for (name, text, needle) in cases {
        let p = tmp(name);
        if let Some(t) = text {
            std::fs::write(&p, t).unwrap();
        }
        for cmd in ["check", "run"] {
            let o = run(&[cmd, p.to_str().unwrap()]);
            assert_eq!(o.status.code(), Some(1), "{cmd} {name}: {}", stderr(&o));
            assert!(stderr(&o).contains(needle), "{cmd} {name}: {}", stderr(&o));
        }
    }
}

/// A `run -o` killed with SIGKILL at several moments leaves a file holding every completed step, and
/// `--resume` then ends bit-identical to an uninterrupted run. The kills land at fractions of the step
/// phase of an uninterrupted run (from the moment its file appears under its name, i.e. after step 0
/// is committed, to its end), so they fall mid-run however fast the machine is.
#[test]
fn sigkill_then_resume_is_bit_identical() {
    sigkill_then_resume("verification/cases/paper_example_5_1.toml", "3", "kill");
}

/// The same with unilateral contact (normal unknowns, whose forces P warm-start the next step and are
/// stored exactly for `--resume`): a resumed run is bit-identical to an uninterrupted one.
#[test]
fn sigkill_then_resume_with_unilateral_contact_is_bit_identical() {
    sigkill_then_resume("verification/cases/mms_signorini_moving.toml", "2", "kill_unilateral");
}

/// Kill `scene` at `refine` (1500 steps) at three moments, resume each and compare (files `<tag>_*.h5`).
fn sigkill_then_resume(scene: &str, refine: &str, tag: &str) {
    let scene = root(scene);
    let args = |out: &Path| -> Vec<String> {
        ["run", &scene, "--refine", refine, "--steps", "1500", "-q", "-o", out.to_str().unwrap()]
            .iter()
            .map(|s| s.to_string())
            .collect()
    };
    // poll until `out` exists (the run's first commit) or the child ends
    let wait_for = |out: &Path, child: &mut std::process::Child| {
        while !out.exists() && child.try_wait().unwrap().is_none() {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
    };
    let full = tmp(&format!("{tag}_full.h5"));
    let start = std::time::Instant::now();
    let mut child = spawn(bin().args(args(&full)).stdout(std::process::Stdio::null()));
    wait_for(&full, &mut child);
    let appeared = start.elapsed();
    assert!(child.wait().unwrap().success());
    let phase = start.elapsed() - appeared;
    let mut killed_mid_run = 0;
    for (i, frac) in [0.1, 0.5, 0.9].into_iter().enumerate() {
        let out = tmp(&format!("{tag}_{i}.h5"));
        let mut child = spawn(bin().args(args(&out)));
        wait_for(&out, &mut child);
        std::thread::sleep(phase.mul_f64(frac));
        let finished = child.try_wait().unwrap().is_some();
        let _ = child.kill(); // SIGKILL on Unix
        let _ = child.wait();
        assert!(out.exists(), "kill {i}: the run's file is not under its name after its first commit");
        // every committed step is readable and equal to the uninterrupted run's
        let held = fork_guard();
        let f = hdf5::File::open(&out).expect("a killed run's file opens");
        let done = f.group("tresca/steps").unwrap().attr("completed").unwrap().read_scalar::<i64>().unwrap() as usize;
        let g = hdf5::File::open(&full).unwrap();
        let (uk, uf) = (
            f.dataset("tresca/u").unwrap().read_raw::<f64>().unwrap(),
            g.dataset("tresca/u").unwrap().read_raw::<f64>().unwrap(),
        );
        let per = uf.len() / 1501;
        assert!(uk.len() >= done * per);
        assert!(
            uk[..done * per].iter().zip(&uf[..done * per]).all(|(a, b)| a.to_bits() == b.to_bits()),
            "kill {i}: committed steps differ"
        );
        drop((f, g));
        drop(held);
        if !finished && done < 1501 {
            killed_mid_run += 1;
        }
        let o = spawn(bin().args(args(&out)).arg("--resume")).wait_with_output().unwrap();
        assert!(o.status.success(), "resume {i}: {}", stderr(&o));
        same_results(&full, &out);
    }
    assert!(killed_mid_run >= 1, "no kill landed in the middle of the run; lengthen it");
}

/// The system shall print no NaN as a study estimate: an output that is not extrapolated shows "—" for
/// its estimate and GCI and says why (a one-step scene whose max_slip and stick_length do not converge
/// monotonically over three levels).
#[test]
fn study_prints_reasons_not_nan() {
    let scene = root("verification/external/scenes/imposed_normal.toml");
    let o = run(&["study", &scene, "--levels", "1:1,2:1,3:1"]);
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.to_lowercase().contains("nan"), "NaN printed:\n{out}");
    assert!(out.contains("Output max_slip at T: not extrapolated: "), "{out}");
    assert!(out.lines().filter(|l| l.contains("est          —  GCI          —")).count() >= 3, "{out}");
}

/// The system shall give the same results files, bit for bit, with 1 and with 2 threads (docs/model.md,
/// "Threads"; refine 5's factor is computed by subtrees), record the count in `/tresca@threads`, and refuse
/// a thread count of 0 or one that is not a number with a message.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let scene = root("verification/cases/paper_example_5_1.toml");
    let files = [tmp("threads_1.h5"), tmp("threads_2.h5")];
    for (t, out) in ["1", "2"].into_iter().zip(&files) {
        let out_s = out.to_str().unwrap();
        let o = run(&["run", &scene, "--refine", "5", "--steps", "4", "-q", "--threads", t, "-o", out_s, "--force"]);
        assert!(o.status.success(), "{}", stderr(&o));
        let f = hdf5::File::open(out).unwrap();
        let n: i64 = f.group("tresca").unwrap().attr("threads").unwrap().read_scalar().unwrap();
        assert_eq!(n.to_string(), t);
    }
    same_results(&files[0], &files[1]);
    let o = run(&["check", &scene, "--threads", "0"]);
    assert!(!o.status.success() && stderr(&o).contains("--threads"), "{}", stderr(&o));
    let o = spawn(bin().env("TRESCA_THREADS", "two").args(["check", &scene])).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("TRESCA_THREADS"), "{}", stderr(&o));
}

/// The system shall report in `check --json` the counts of the asked level — `unknowns`, `paper_dofs`,
/// `contact_unknowns`, `edges` — also above `check`'s assembly cap (100,000 unknowns), where the level is
/// counted from a coarser one: the same numbers `run --json` reports at that level, for a scene without
/// normal unknowns (one per contact edge) and one with a unilateral part (two per contact edge).
#[test]
fn check_json_counts_the_asked_level_beyond_the_cap() {
    let read = |p: &Path| -> serde_json::Value { serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap() };
    for case in ["mms_stop", "mms_signorini_stop"] {
        // 17 × 17 cells at refine 3: 136 × 136, 111,112 and 111,248 unknowns, above the cap; refine 2 below it
        let text = std::fs::read_to_string(root(&format!("verification/cases/{case}.toml"))).unwrap();
        assert!(text.contains("cells    = [4, 4]"), "{case}: the test edits the cells line");
        let scene = tmp(&format!("{case}_17.toml"));
        std::fs::write(&scene, text.replace("cells    = [4, 4]", "cells    = [17, 17]")).unwrap();
        let (scene, cj, rj) =
            (scene.display().to_string(), tmp(&format!("{case}_check.json")), tmp(&format!("{case}_run.json")));
        let o = run(&["check", &scene, "--refine", "3", "--json", cj.to_str().unwrap(), "--force"]);
        assert!(o.status.success(), "{case}: {}", stderr(&o));
        assert!(
            String::from_utf8_lossy(&o.stdout).contains("counted, not assembled"),
            "{case}: refine 3 was assembled"
        );
        let o = run(&["run", &scene, "--refine", "3", "--steps", "1", "-q", "--json", rj.to_str().unwrap(), "--force"]);
        assert!(o.status.success(), "{case}: {}", stderr(&o));
        let (c, r) = (read(&cj)["check"].clone(), read(&rj)["run"].clone());
        assert!(c["unknowns"].as_u64().unwrap() > 100_000, "{case}: {c}");
        assert_eq!(c["unknowns"], r["unknowns"], "{case}");
        assert_eq!(c["paper_dofs"], r["paper_dofs"], "{case}");
        let per_edge = if case == "mms_signorini_stop" { 2 } else { 1 };
        assert_eq!(c["contact_unknowns"].as_u64(), r["contact_edges"].as_u64().map(|e| per_edge * e), "{case}");
        // 136 × 136 cells: 3·136² + 2·136 edges
        assert_eq!(c["edges"].as_u64(), Some(3 * 136 * 136 + 2 * 136), "{case}");
    }
}

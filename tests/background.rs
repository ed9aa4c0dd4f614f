//! The writer thread (`output::Background`): a run written through it gives the file a writer on the
//! caller's thread gives, and a step it fails to write stops the run with that error (reported once, by a
//! later `write_step` or by `finish`), leaving the steps before it committed and the file marked stopped.

mod common;

use std::path::{Path, PathBuf};
use tresca_cr::output::{Background, Run, Writer};
use tresca_cr::{Problem, Scene, StepResult};

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("tresca-background", name)
}

fn example(steps: usize) -> Problem {
    example_at(0, steps)
}

fn example_at(refine: u32, steps: usize) -> Problem {
    let mut s: Scene = common::scene("verification/cases/paper_example_5_1.toml");
    s.set_refine(refine).unwrap();
    s.set_steps(steps).unwrap();
    Problem::new(s).unwrap()
}

fn steps(p: &Problem) -> Vec<StepResult> {
    let mut out = Vec::new();
    p.run(tresca_cr::RunOptions::all(), |r| {
        out.push(r.clone());
        Ok(())
    })
    .unwrap();
    out
}

fn completed(path: &Path) -> (i64, String) {
    let f = hdf5::File::open(path).unwrap();
    let n = f.group("tresca/steps").unwrap().attr("completed").unwrap().read_scalar::<i64>().unwrap();
    let s = f.group("tresca").unwrap().attr("status").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap();
    (n, s.as_str().to_string())
}

/// Hand `rs` to a background writer of a new file at `path`, step `bad` with a non-finite u[1] (found on
/// the caller's thread) or μ[0] (found on the writer thread); returns the errors of `write_step` and of
/// `finish`.
fn write(
    p: &Problem,
    path: &Path,
    rs: &[StepResult],
    bad: Option<(usize, &str)>,
) -> (Vec<String>, Result<usize, String>) {
    let mut w = Background::spawn(Writer::create(path, &Run::of(p), true).unwrap()).unwrap();
    let mut errors = Vec::new();
    for r in rs {
        let mut r = r.clone();
        match bad {
            Some((n, "u")) if n == r.n => r.u[1] = f64::NAN,
            Some((n, _)) if n == r.n => r.mu[0] = f64::INFINITY,
            _ => {}
        }
        if let Err(e) = w.write_step(&r) {
            errors.push(e.to_string());
        }
    }
    (errors, w.finish("completed").map_err(|e| e.to_string()))
}

/// Write the 40 steps of Example 5.1 at `refine` with a writer on this thread, step by step, and with a
/// background writer, all steps handed over at once; both files must hold 41 completed steps. Returns
/// the two files.
fn sync_and_background(refine: u32, name: &str) -> (hdf5::File, hdf5::File) {
    let p = example_at(refine, 40);
    let rs = steps(&p);
    let (a, b) = (tmp(&format!("{name}_sync.h5")), tmp(&format!("{name}_thread.h5")));
    let mut w = Writer::create(&a, &Run::of(&p), true).unwrap();
    rs.iter().try_for_each(|r| w.write_step(r)).unwrap();
    w.finish("completed").unwrap();
    let (errors, done) = write(&p, &b, &rs, None);
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(done, Ok(41));
    assert_eq!(completed(&b), (41, "completed".to_string()));
    (hdf5::File::open(&a).unwrap(), hdf5::File::open(&b).unwrap())
}

fn f64s(f: &hdf5::File, name: &str) -> Vec<f64> {
    f.dataset(name).unwrap().read_raw::<f64>().unwrap()
}

#[test]
fn a_background_run_commits_every_step() {
    let (a, b) = sync_and_background(0, "steps");
    for name in ["tresca/u", "tresca/contact/mu", "tresca/times", "tresca/energy"] {
        assert_eq!(f64s(&a, name), f64s(&b, name), "{name}");
    }
}

/// Requirement: the writer commits a group of queued steps in pieces once it holds 4 MB of rows and frames
/// (`output::rows::BUDGET`, so its buffers stay small), and the file is the one a writer on the caller's
/// thread writes step by step. At refine 4 a step is about 0.23 MB of rows and frames, and the 40 steps,
/// handed over at once, queue up far beyond 4 MB (the group is cut after 19 steps).
#[test]
fn a_group_beyond_the_byte_budget_is_committed_in_pieces_to_the_same_file() {
    let (a, b) = sync_and_background(4, "budget");
    for name in ["tresca/u", "tresca/contact/mu", "tresca/times", "VTKHDF/body/Steps/Values"] {
        assert_eq!(f64s(&a, name), f64s(&b, name), "{name}");
    }
    let f32s = |f: &hdf5::File, name: &str| f.dataset(name).unwrap().read_raw::<f32>().unwrap();
    for name in [
        "VTKHDF/body/PointData/displacement",
        "VTKHDF/body/CellData/stress",
        "VTKHDF/contact/PointData/displacement",
        "VTKHDF/contact/CellData/slip",
    ] {
        assert_eq!(f32s(&a, name), f32s(&b, name), "{name}");
    }
    let nsteps =
        |f: &hdf5::File| f.group("VTKHDF/body/Steps").unwrap().attr("NSteps").unwrap().read_scalar::<i64>().unwrap();
    assert_eq!((nsteps(&a), nsteps(&b)), (41, 41));
}

#[test]
fn a_write_error_on_the_writer_thread_stops_the_run() {
    let p = example(40);
    let rs = steps(&p);
    for (bad, what) in [(5, "u"), (40, "u"), (5, "mu"), (40, "mu")] {
        let path = tmp(&format!("bad{bad}{what}.h5"));
        let (errors, done) = write(&p, &path, &rs, Some((bad, what)));
        // the error is reported exactly once: by a later write_step, or by finish
        let all: Vec<String> = errors.into_iter().chain(done.clone().err()).collect();
        assert_eq!(all.len(), 1, "bad step {bad}: {all:?}");
        let index = if what == "u" { 1 } else { 0 };
        assert!(all[0].contains(&format!("step {bad}: {what}[{index}] is not finite")), "{}", all[0]);
        if (bad, what) == (40, "mu") {
            assert!(done.is_err(), "an error of the writer thread at the last step must fail finish");
        }
        let (n, status) = completed(&path);
        assert_eq!(n, bad as i64, "the steps before the bad one are committed, none after it");
        assert!(status.starts_with("stopped: ") && status.contains("not finite"), "{status}");
    }
}

#[test]
fn a_dropped_background_writer_closes_its_file() {
    let p = example(40);
    let rs = steps(&p);
    let path = tmp("dropped.h5");
    let mut w = Background::spawn(Writer::create(&path, &Run::of(&p), true).unwrap()).unwrap();
    rs[..10].iter().try_for_each(|r| w.write_step(r)).unwrap();
    drop(w);
    let (n, status) = completed(&path);
    assert_eq!(n, 10);
    assert!(status.starts_with("stopped: "), "{status}");
}

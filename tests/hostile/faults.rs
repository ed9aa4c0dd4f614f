//! Issue 43 §4: a disk that fills in the middle of a run or of `adapt`, on a small tmpfs mounted for the
//! test (skipped, saying so, where mounting is not permitted; unmounted in all cases).

use super::{s, scene_with, tmp};
use crate::common::{bin, fork_guard, same_results, spawn, stderr};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use tresca_cr::output::{Run, Writer};
use tresca_cr::{Problem, RunOptions, Scene};

/// A tmpfs of a given size mounted on a directory of its own, unmounted when dropped.
struct Tmpfs {
    dir: PathBuf,
}

impl Tmpfs {
    fn mount(name: &str, size: &str) -> Option<Tmpfs> {
        let dir = tmp(name);
        std::fs::create_dir_all(&dir).unwrap();
        let o = Command::new("mount").args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs", s(&dir)]).output();
        match o {
            Ok(o) if o.status.success() => Some(Tmpfs { dir }),
            o => {
                let why = o.map_or_else(|e| e.to_string(), |o| stderr(&o));
                eprintln!("SKIPPED: cannot mount a {size} tmpfs on {} (needs root): {why}", dir.display());
                None
            }
        }
    }

    /// Fill what is left of the file system with a file of its own (every page, up to ENOSPC).
    fn fill(&self) -> PathBuf {
        let p = self.dir.join("filler");
        let mut f = std::fs::File::create(&p).unwrap();
        for chunk in [1 << 16, 1 << 12, 1] {
            let buf = vec![1u8; chunk];
            while f.write_all(&buf).is_ok() {}
        }
        assert!(f.write_all(&[1]).is_err(), "the file system is not full");
        p
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let ok = Command::new("umount").arg(&self.dir).status().is_ok_and(|s| s.success());
        if !ok {
            let _ = Command::new("umount").arg("-l").arg(&self.dir).status();
        }
    }
}

/// Example 5.1 on its 2 × 2 cells, 40 steps (a frame at every step).
fn scene40() -> String {
    scene_with("enospc.toml", "steps = 40", "steps = 40")
}

/// §4: the system shall keep every committed step of a run whose disk fills in the middle of it: the run
/// stops naming the disk, the file holds its committed steps (checksums verified by `--resume`), and once
/// there is room again `--resume` finishes it bit-identically to a run that never stopped.
#[test]
fn a_disk_that_fills_mid_run_loses_no_committed_step() {
    let Some(fs) = Tmpfs::mount("enospc-run", "4m") else { return };
    let scene = scene40();
    let out = fs.dir.join("r.h5");
    let (committed, error, filler) = {
        let _g = fork_guard();
        let problem = Problem::new(Scene::from_file(Path::new(&scene)).unwrap()).unwrap();
        let mut w = Writer::create(&out, &Run::of(&problem), false).unwrap();
        let mut filler = None;
        let result = problem.run(RunOptions::all(), |r| {
            if r.n == 1 {
                // step 0 is committed: now the disk fills
                filler = Some(fs.fill());
            }
            w.write_step(r)
        });
        let error = result.err().map(|e| e.to_string());
        let status = error.as_ref().map_or("completed".to_string(), |e| format!("stopped: {e}"));
        // closing may itself find no room to record the status: the file then stays as a killed run's
        let closed = w.finish(&status).map_err(|e| e.to_string());
        (closed, error, filler.unwrap())
    };
    for e in error.iter().chain(committed.as_ref().err()) {
        assert!(e.contains("No space left on device") || e.contains("no room on the disk"), "{e}");
    }
    let _ = committed;
    std::fs::remove_file(filler).unwrap();
    let o = spawn(bin().args(["run", &scene, "-q", "-o", s(&out), "--resume"])).wait_with_output().unwrap();
    assert!(o.status.success(), "--resume after the full disk: {}", stderr(&o));
    let whole = tmp("enospc-whole.h5");
    let _ = std::fs::remove_file(&whole);
    let o = spawn(bin().args(["run", &scene, "-q", "-o", s(&whole)])).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let _g = fork_guard();
    same_results(&out, &whole);
}

/// §4: the system shall end `adapt` on a disk that fills in the middle of its levels with a clear error
/// (exit code 1, never a signal), leaving every level written before complete. (`--max-disk` stands for
/// the estimate's answer on a disk another process fills meanwhile.)
#[test]
fn adapt_on_a_disk_that_fills_ends_with_an_error_not_a_signal() {
    let Some(fs) = Tmpfs::mount("enospc-adapt", "3m") else { return };
    let scene = scene40();
    let dir = fs.dir.join("adapt");
    let args = ["adapt", &scene, "--refine", "1", "--levels", "6", "--out", s(&dir), "--max-disk", "1T"];
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("no room on the disk"), "{}", stderr(&o));
    let mut levels = 0;
    let _g = fork_guard();
    for k in 0.. {
        let p = dir.join(format!("level_{k}.h5"));
        if !p.exists() {
            break;
        }
        let f = hdf5::File::open(&p).unwrap();
        let g = f.group("tresca").unwrap();
        let status = g.attr("status").unwrap().read_scalar::<hdf5::types::VarLenUnicode>().unwrap();
        let completed = g.group("steps").unwrap().attr("completed").unwrap().read_scalar::<i64>().unwrap();
        assert_eq!((status.as_str(), completed), ("completed", 41), "{}", p.display());
        levels += 1;
    }
    assert!(levels >= 1, "no level was written: {}", stderr(&o));
}

/// `args` run with standard output closed (`>&-`).
fn with_stdout_closed(args: &[&str]) -> std::process::Output {
    use std::os::unix::process::CommandExt;
    let _g = fork_guard();
    let mut c = bin();
    c.args(args);
    // SAFETY: closing descriptor 1 in the child between fork and exec.
    unsafe {
        c.pre_exec(|| {
            libc::close(1);
            Ok(())
        });
    }
    c.output().unwrap()
}

/// §5: the system shall fail `adapt` whose table is lost (standard output closed or full) as `study` and
/// `plan` fail, naming the cause, and say that --csv keeps the table.
#[test]
fn adapt_with_its_standard_output_lost_fails() {
    let scene = scene40();
    let args = ["adapt", scene.as_str(), "--levels", "2"];
    let o = with_stdout_closed(&args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot write to standard output"), "{}", stderr(&o));
    if Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = {
            let _g = fork_guard();
            bin().args(args).stdout(full).output().unwrap()
        };
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("--csv keeps it"), "{}", stderr(&o));
    }
}

/// §5: the system shall refuse `adapt --reference 0` (the starting mesh, not finer than any level) before
/// any level runs, refuse a reference solve whose memory does not fit before it runs (exit code 3, the
/// reason named), and refuse an existing level file suggesting only what adapt does (--force, not
/// --resume).
#[test]
fn adapt_refuses_what_it_cannot_do_as_run_does() {
    let scene = scene40();
    let o = spawn(bin().args(["adapt", &scene, "--levels", "2", "--reference", "0"])).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--reference 0") && stderr(&o).contains("not finer"), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).lines().count() <= 1, "a level ran");
    let args = ["adapt", &scene, "--levels", "2", "--reference", "12", "--max-memory", "100M"];
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("reference solve") && stderr(&o).contains("does not fit"), "{}", stderr(&o));
    let dir = tmp("adapt-again");
    let _ = std::fs::remove_dir_all(&dir);
    let args = ["adapt", &scene, "--levels", "1", "--out", s(&dir)];
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--force") && !stderr(&o).contains("--resume"), "{}", stderr(&o));
}

/// §5: the system shall refuse `adapt --reference G` when every triangle of a level has generation G or
/// more (uniform levels: level k has generation k), naming the generation and the level, before that level
/// is solved: the reference would be that level's own mesh, an effectivity against itself. One generation
/// more is a reference.
#[test]
fn adapt_refuses_a_reference_not_finer_than_its_levels() {
    let scene = scene_with("not_finer.toml", "steps = 40", "steps = 4");
    let args = ["adapt", &scene, "--levels", "3", "--theta", "1", "--reference", "2"];
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(
        e.contains("--reference 2: every triangle of level 2 already has generation 2") && e.contains("not finer"),
        "{e}"
    );
    let args = ["adapt", &scene, "--levels", "3", "--theta", "1", "--reference", "3"];
    let o = spawn(bin().args(args)).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("vs ref"), "no reference measured");
}

/// §5: the system shall refuse a study whose level does not fit under the process's address-space limit
/// (`ulimit -v`) even when --max-memory allows it, naming the limit, before any level runs.
#[test]
fn study_max_memory_is_checked_against_the_address_space_limit() {
    use std::os::unix::process::CommandExt;
    let scene = scene40();
    let o = {
        let _g = fork_guard();
        let mut c = bin();
        c.args(["study", &scene, "--levels", "0:4,7:8", "--max-memory", "100G"]);
        // SAFETY: setrlimit in the child between fork and exec (`ulimit -v 800000`, in KiB).
        unsafe {
            c.pre_exec(|| {
                let lim = libc::rlimit { rlim_cur: 800_000 << 10, rlim_max: 800_000 << 10 };
                libc::setrlimit(libc::RLIMIT_AS, &lim);
                Ok(())
            });
        }
        c.output().unwrap()
    };
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("ulimit -v") && stderr(&o).contains("study level 7:8"), "{}", stderr(&o));
    assert!(o.stdout.is_empty(), "a level ran");
}

//! Hostile inputs of issue 34, one test per class, through the release binary where the fault is a
//! process-level one: links, devices and FIFOs planted under the names a run writes (§1), closed pipes
//! and studies that cannot fit (§2), scene arrays longer than the schema and other silent wrong answers
//! (§3), inputs that would be read forever (§4), and messages that blamed the wrong cause (§5). The
//! inputs that are scenes are also in `tests/fuzz_corpus/` (replayed by `tests/fuzz.rs`).

#[path = "hostile/beyond_machine.rs"]
mod beyond_machine;
#[path = "hostile/budget.rs"]
mod budget;
mod common;
#[path = "hostile/damaged_resume.rs"]
mod damaged_resume;
#[path = "hostile/faults.rs"]
mod faults;
#[path = "hostile/outputs.rs"]
mod outputs;
use common::{bin, root, spawn, stderr};
use std::os::unix::fs::FileTypeExt;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

#[path = "hostile/threads.rs"]
mod threads;
#[path = "hostile/validation.rs"]
mod validation;

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("tresca-hostile", name)
}

/// Threads of a run that may multiply dense blocks at once (the two factorisation workers, the main thread
/// and the condition estimate's), each reserving [`kernel_reserve`] bytes of address space.
const KERNEL_THREADS: u64 = 4;

/// The address space private-gemm-x86 (faer's matrix-product kernel) reserves on each thread that multiplies,
/// on first use: a packing buffer of twice the L3 cache the machine reports, whose refusal aborts the
/// process (an allocation failure, not an error it returns). On a VM reporting a 480 MiB L3 that is 960 MiB
/// a thread; on common machines tens of MiB. Read as the crate reads it: level 3 of cpu0's caches in sysfs.
fn kernel_reserve() -> u64 {
    let dir = std::path::Path::new("/sys/devices/system/cpu/cpu0/cache");
    let read = |p: PathBuf, f: &str| std::fs::read_to_string(p.join(f)).ok().map(|t| t.trim().to_string());
    let l3 = std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .filter(|p| read(p.clone(), "level").as_deref() == Some("3"))
        .filter_map(|p| read(p, "size"))
        .filter_map(|s| s.strip_suffix('K').and_then(|k| k.parse::<u64>().ok()).map(|k| k << 10))
        .max()
        .unwrap_or(0);
    2 * l3
}

/// `cmd` with its address space limited to `bytes` (`setrlimit(RLIMIT_AS)` in the child), plus the dense
/// kernel's reservation on [`KERNEL_THREADS`] threads (`kernel_reserve`): the limits these tests set are
/// for the run's own memory and thread stacks.
fn address_space(cmd: &mut Command, bytes: u64) -> &mut Command {
    let bytes = bytes + KERNEL_THREADS * kernel_reserve();
    // SAFETY: setrlimit in the child between fork and exec.
    unsafe {
        cmd.pre_exec(move || {
            let lim = libc::rlimit { rlim_cur: bytes, rlim_max: bytes };
            libc::setrlimit(libc::RLIMIT_AS, &lim);
            Ok(())
        })
    }
}

fn run(args: &[&str]) -> Output {
    spawn(bin().args(args)).wait_with_output().unwrap()
}

/// Example 5.1 (2 × 2 cells, 40 steps) as a scene file of its own, with `from` replaced by `to`.
fn scene_with(name: &str, from: &str, to: &str) -> String {
    let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml")).unwrap();
    assert!(text.contains(from), "{from}");
    let p = tmp(name);
    // written beside it and renamed: tests running at once write the same scene, and a reader must never see
    // it half written
    let part = tmp(&format!("{name}.{:?}", std::thread::current().id()));
    std::fs::write(&part, text.replace(from, to)).unwrap();
    std::fs::rename(&part, &p).unwrap();
    p.display().to_string()
}

fn base() -> String {
    scene_with("base.toml", "steps = 40", "steps = 4")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Nothing this run makes is left beside `out` (lock, partial files).
fn no_leftovers(out: &Path) {
    for ext in [".lock", ".partial"] {
        let mut p = out.as_os_str().to_owned();
        p.push(ext);
        assert!(!Path::new(&p).exists(), "{} left behind", Path::new(&p).display());
    }
    let side = out.with_extension("xdmf.partial");
    assert!(!side.exists(), "{} left behind", side.display());
}

/// §1: the system shall never write through a symbolic or hard link planted under the name of its lock
/// or partial files, never replace a device or FIFO, and refuse each naming what the path is.
#[test]
fn planted_links_devices_and_fifos_are_refused() {
    let scene = base();
    for (planted, kind, want) in [
        ("r1.h5.lock", "symlink", "symbolic link"),
        ("r2.h5.lock", "hardlink", "2 link"),
        ("r3.h5.partial", "symlink", "symbolic link"),
        ("r4.h5.partial", "hardlink", "2 hard links"),
        ("r5.xdmf.partial", "symlink", "symbolic link"),
        ("r6.xdmf.partial", "hardlink", "2 hard links"),
    ] {
        let victim = tmp(&format!("victim_{planted}"));
        std::fs::write(&victim, b"V\n").unwrap();
        let link = tmp(planted);
        let _ = std::fs::remove_file(&link);
        match kind {
            "symlink" => std::os::unix::fs::symlink(&victim, &link).unwrap(),
            _ => std::fs::hard_link(&victim, &link).unwrap(),
        }
        let out = tmp(&format!("{}.h5", &planted[..2]));
        let _ = std::fs::remove_file(&out);
        let o = run(&["run", &scene, "-q", "-o", s(&out)]);
        assert_eq!(o.status.code(), Some(1), "{planted}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{planted}: {}", stderr(&o));
        assert_eq!(std::fs::read(&victim).unwrap(), b"V\n", "{planted}: the victim was written");
        assert!(!out.exists(), "{planted}: a results file was made");
        assert!(std::fs::symlink_metadata(&link).is_ok(), "{planted}: the planted name was removed");
    }
    // a symbolic link as the results file itself, even with --force
    let victim = tmp("victim_target");
    std::fs::write(&victim, b"V\n").unwrap();
    let link = tmp("linked.h5");
    let _ = std::fs::remove_file(&link);
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let o = run(&["run", &scene, "-q", "-o", s(&link), "--force"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    no_leftovers(&link);
    // a FIFO: refused at once, nothing left (it used to block, leaving .lock and .partial)
    let fifo = tmp("fifo.h5");
    let _ = std::fs::remove_file(&fifo);
    let c = std::ffi::CString::new(s(&fifo)).unwrap();
    // SAFETY: mkfifo on a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    let o = run(&["run", &scene, "-q", "-o", s(&fifo), "--force"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("FIFO"), "{}", stderr(&o));
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
    no_leftovers(&fifo);
    // a character device under --force (made here where mknod is allowed, never /dev/null itself)
    let dev = tmp("null_device.h5");
    let _ = std::fs::remove_file(&dev);
    let c = std::ffi::CString::new(s(&dev)).unwrap();
    // SAFETY: mknod of a character device (1, 3: the null device) on a NUL-terminated path.
    if unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) } == 0 {
        let o = run(&["run", &scene, "-q", "-o", s(&dev), "--force"]);
        assert_eq!(o.status.code(), Some(1));
        assert!(stderr(&o).contains("character device"), "{}", stderr(&o));
        assert!(std::fs::symlink_metadata(&dev).unwrap().file_type().is_char_device());
        no_leftovers(&dev);
    }
    // a stale lock of a killed run (a regular file of its own) is still taken over
    let out = tmp("stale.h5");
    let _ = std::fs::remove_file(&out);
    std::fs::write(tmp("stale.h5.lock"), b"12345 (dead)").unwrap();
    std::fs::write(tmp("stale.h5.partial"), b"unfinished").unwrap();
    let o = run(&["run", &scene, "-q", "-o", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    no_leftovers(&out);
}

/// §1, §3, §5: the system shall refuse `-o x.xdmf` (its own sidecar's name) and a directory it cannot
/// create files in with a message saying so, and shall not overwrite an unrelated XDMF file without
/// --force; none leaves a file behind.
#[test]
fn output_names_that_cannot_be_results_are_refused() {
    let scene = base();
    let xdmf = tmp("run.xdmf");
    let o = run(&["run", &scene, "-q", "-o", s(&xdmf)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot end in .xdmf"), "{}", stderr(&o));
    assert!(!xdmf.exists());
    no_leftovers(&xdmf);
    let o = run(&["run", &scene, "-q", "-o", "/proc/self/x.h5"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("cannot create"), "{}", stderr(&o));
    let out = tmp("unrelated.h5");
    let _ = std::fs::remove_file(&out);
    std::fs::write(out.with_extension("xdmf"), b"mine").unwrap();
    let o = run(&["run", &scene, "-q", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    assert_eq!(std::fs::read(out.with_extension("xdmf")).unwrap(), b"mine");
    assert!(!out.exists());
    let o = run(&["run", &scene, "-q", "-o", s(&out), "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// §2, §3: the system shall never panic on a closed or full standard output: `study` and `plan` end
/// cleanly when the reader of their pipe goes away, and `check` (`>&-`) and `plan` (`>/dev/full`) fail
/// with a message, as the README says, while `run >&-` reports it at the end.
#[test]
fn lost_standard_output_is_reported_not_a_panic() {
    let scene = base();
    for args in [vec!["study", &scene, "--levels", "0:4,1:8,2:16"], vec!["check", &scene]] {
        let mut c = bin();
        let mut child = spawn(c.args(&args).stdout(Stdio::piped()).stderr(Stdio::piped()));
        drop(child.stdout.take()); // the reader goes away at once (`| head -0`)
        let o = child.wait_with_output().unwrap();
        assert!(!stderr(&o).contains("panicked"), "{args:?}: {}", stderr(&o));
        assert_ne!(o.status.code(), Some(101), "{args:?}");
    }
    let closed = |args: &[&str]| {
        let mut c = bin();
        c.args(args);
        // SAFETY: closing descriptor 1 in the child between fork and exec (`>&-`).
        unsafe {
            c.pre_exec(|| {
                libc::close(1);
                Ok(())
            });
        }
        c.output().unwrap()
    };
    let o = closed(&["check", &scene]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output is closed"), "{}", stderr(&o));
    let o = closed(&["run", &scene, "-q"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("standard output could not be written"), "{}", stderr(&o));
    if Path::new("/dev/full").exists() {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
        let o = bin().args(["plan", &scene, "--target", "1e-2", "--pilot-budget", "5s"]).stdout(full).output().unwrap();
        assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
        assert!(stderr(&o).contains("cannot write to standard output"), "{}", stderr(&o));
    }
}

/// §2, §3: the system shall refuse a study whose levels make no sense (a level twice, out of order, a
/// reference not finer than every level) or cannot fit in memory, before running any level, and shall
/// refuse a --csv that is the scene.
#[test]
fn studies_that_make_no_sense_or_cannot_fit_are_refused() {
    let scene = base();
    for (args, want) in [
        (vec!["--levels", "0:4,0:4"], "given twice"),
        (vec!["--levels", "1:8,0:4"], "coarse to fine"),
        (vec!["--levels", "0:4,1:8", "--reference", "1:8"], "finer than every level"),
        (vec!["--levels", "0:4,1:8", "--reference", "0:2"], "finer than every level"),
        (vec!["--levels", "0:4,9:8", "--max-memory", "1G"], "study level 9:8"),
        (vec!["--levels", "0:4,1:8", "--reference", "12:8", "--max-memory", "1G"], "--reference 12:8"),
    ] {
        let start = std::time::Instant::now();
        let o = run(&[&["study", scene.as_str()], args.as_slice()].concat());
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
        assert!(o.stdout.is_empty(), "{args:?}: a level ran");
        let _ = start;
    }
    let before = std::fs::read(&scene).unwrap();
    for args in [
        vec!["study", &scene, "--levels", "0:4,1:8", "--csv", &scene],
        vec!["plan", &scene, "--target", "1", "--csv", &scene],
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(1), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("overwrite the run's input"), "{args:?}: {}", stderr(&o));
        assert_eq!(std::fs::read(&scene).unwrap(), before);
    }
    // a quantity measured on Γ_C of a scene without contact: refused before any pilot runs
    let nocontact = scene_with("nocontact.toml", "kind = \"contact\"\ng_a = \"0.0012\"", "kind = \"neumann\"");
    let o = run(&["plan", &nocontact, "--target", "1e-3", "--quantity", "max-slip"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("has none"), "{}", stderr(&o));
    assert!(!String::from_utf8_lossy(&o.stdout).contains("Pilot"), "pilots ran");
}

/// §3: the system shall refuse scene arrays longer than the schema expects (not cut them), uniform time
/// steps that collapse in floating point and non-finite output points, naming the key or line.
#[test]
fn scene_arrays_and_values_that_were_silently_cut_are_refused() {
    let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml")).unwrap();
    let corners = "corners = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]";
    let traction = r#"traction = ["0.02*(5-y)*t", "-0.01*t"]"#;
    let exact = "\n[exact]\nu = [\"0\", \"0\"]\ngrad = [[\"0\", \"0\"], [\"0\", \"0\"], [\"0\", \"0\"]]\n";
    for (from, to, want) in [
        ("cells = [2, 2]", "cells = [2, 2, 2]", "expected 2 values, found 3"),
        (corners, "corners = [[0.0, 0.0], [4.0, 0.0], [5.0, 2.0], [4.0, 4.0], [0.0, 4.0]]", "found 5"),
        (corners, "corners = [[0.0, 0.0, 1.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]", "expected 2 values, found 3"),
        (traction, r#"traction = ["0.02*(5-y)*t", "-0.01*t", "1"]"#, "expected 2 values, found 3"),
        ("steps = 40", "steps = 40\n", "expected 2 values, found 3"), // with the 3 × 2 grad below
        ("T = 1.0", "T = 5e-324", "collapse"),
        ("steps = 40", "steps = 40\n[outputs]\ntraction_at = [[nan, 0.0]]\n", "not finite"),
        ("steps = 40", "steps = 40\n[outputs]\ntraction_at = [[1.0, 0.0, 0.0]]\n", "expected 2 values, found 3"),
    ] {
        assert!(text.contains(from), "{from}");
        let mut t = text.replace(from, to);
        if to == "steps = 40\n" {
            t += exact;
        }
        if from == "T = 1.0" {
            t = t.replace("steps = 40", "steps = 8");
        }
        let e = tresca_cr::Scene::from_str(&t, "hostile.toml").expect_err(to).to_string();
        assert!(e.contains(want), "{to}: {e}");
    }
}

/// §3: the system shall refuse to write a frame whose displacement is nonzero in f64 but below the
/// single-precision range of the ParaView views (which would show zeros), as it refuses overflow; the
/// f64 answer is still computed without a results file.
#[test]
fn views_that_would_underflow_are_refused() {
    let tiny = scene_with(
        "tiny_loads.toml",
        r#"traction = ["0.02*(5-y)*t", "-0.01*t"]"#,
        r#"traction = ["1e-300*0.02*(5-y)*t", "-1e-300*0.01*t"]"#,
    );
    let tiny = {
        let t = std::fs::read_to_string(&tiny).unwrap().replace(r#"g_a = "0.0012""#, r#"g_a = "1e-300*0.0012""#);
        std::fs::write(&tiny, t).unwrap();
        tiny
    };
    let out = tmp("tiny.h5");
    let _ = std::fs::remove_file(&out);
    let o = run(&["run", &tiny, "-q", "-o", s(&out), "--steps", "4"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("below the single-precision range"), "{}", stderr(&o));
    let o = run(&["run", &tiny, "-q", "--steps", "4"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// §4: the system shall refuse input paths that are not regular files (a device that never ends, a FIFO
/// without a writer) at once, naming what they are, and `check` shall count a level too large to set up
/// quickly instead of building it, printing the same counts the built level has.
#[test]
fn inputs_that_never_end_are_refused_and_check_estimates() {
    let fifo = tmp("scene_fifo.toml");
    let _ = std::fs::remove_file(&fifo);
    let c = std::ffi::CString::new(s(&fifo)).unwrap();
    // SAFETY: mkfifo on a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
    for (path, want) in [("/dev/zero", "character device"), (s(&fifo), "FIFO")] {
        let o = run(&["check", path]);
        assert_eq!(o.status.code(), Some(1), "{path}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{path}: {}", stderr(&o));
    }
    let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml")).unwrap();
    let keep = |l: &&str| !["corners", "cells", "diagonal"].iter().any(|k| l.starts_with(k));
    let text =
        text.lines().filter(keep).collect::<Vec<_>>().join("\n").replace("[mesh]", "[mesh]\nfile = \"/dev/zero\"");
    let mesh = tmp("zero_mesh.toml");
    std::fs::write(&mesh, text).unwrap();
    let mesh = mesh.display().to_string();
    let o = run(&["check", &mesh]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("cannot read mesh") && stderr(&o).contains("character device"), "{}", stderr(&o));
    // refine 7 (393,000 unknowns) is counted from refine 6; the counts are those of the built level
    let ex = root("verification/cases/paper_example_5_1.toml");
    let o = run(&["check", &ex, "--refine", "7"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("counted, not assembled"), "{text}");
    // 256 × 256 cells: 2·256² triangles, 3·256² + 2·256 edges, 257² vertices
    assert!(text.contains("66049 vertices, 131072 triangles, 197120 edges"), "{text}");
    // unknowns: 2 per free edge, 1 per contact edge; right is Dirichlet (256 edges), bottom contact (256)
    assert!(text.contains(&format!("unknowns   {}", 2 * (197120 - 512) + 256)), "{text}");
}

/// §5: the system shall name overflow and underflow of the data as such (not a missing Dirichlet part
/// or a degenerate mesh), name the flag and its rule for negative numeric options, and call damage to a
/// results file damage on --resume, not a change of settings.
#[test]
fn messages_name_the_cause() {
    for (from, to, want) in [
        ("E = 200.0", "E = 1e308", "overflow"),
        ("E = 200.0", "E = 5e-324", "underflow"),
        ("rho = 10.0", "rho = 1e300", "overflow"),
        ("rho = 10.0", "rho = 1e-300", "underflow"),
        ("[4.0, 4.0]", "[4e300, 4e300]", "overflows"),
    ] {
        let p = scene_with("msg.toml", from, to);
        let o = run(&["check", &p]);
        assert_eq!(o.status.code(), Some(1), "{to}: {}", stderr(&o));
        assert!(stderr(&o).contains(want) && !stderr(&o).contains("Dirichlet part?"), "{to}: {}", stderr(&o));
    }
    let scene = base();
    for (args, flag) in [
        (vec!["run", &scene, "--steps", "-5"], "--steps"),
        (vec!["run", &scene, "--tol", "-1"], "--tol"),
        (vec!["check", &scene, "--refine", "-1"], "--refine"),
        (vec!["check", &scene, "--max-memory", "-5G"], "--max-memory"),
        (vec!["study", &scene, "--levels", "-1:4"], "--levels"),
        (vec!["plan", &scene, "--target", "-1"], "--target"),
    ] {
        let o = run(&args);
        assert!(matches!(o.status.code(), Some(1 | 2)), "{args:?}");
        let e = stderr(&o);
        assert!(e.contains(flag) && !e.contains("unexpected argument"), "{args:?}: {e}");
        assert!(e.contains("positive") || e.contains("whole number") || e.contains("negative"), "{args:?}: {e}");
    }
    // --resume over a damaged time grid, mesh or raised counter: damage, not "a different run"
    let out = tmp("damaged.h5");
    let damage = |what: &str| {
        let _ = std::fs::remove_file(&out);
        let o = run(&["run", &scene, "-q", "-o", s(&out), "--force"]);
        assert!(o.status.success(), "{}", stderr(&o));
        {
            let _g = common::fork_guard();
            let f = hdf5::File::open_rw(&out).unwrap();
            match what {
                "times" | "points" => {
                    let ds = f.dataset(if what == "times" { "tresca/times" } else { "tresca/mesh/points" }).unwrap();
                    let mut v: Vec<f64> = ds.read_raw().unwrap();
                    v[2] += 0.5;
                    ds.write_raw(&v).unwrap();
                }
                _ => f.group("tresca/steps").unwrap().attr("completed").unwrap().write_scalar(&9i64).unwrap(),
            }
        }
        let o = run(&["run", &scene, "-q", "-o", s(&out), "--resume"]);
        assert_eq!(o.status.code(), Some(1), "{what}: {}", stderr(&o));
        assert!(stderr(&o).contains("damaged") && !stderr(&o).contains("different"), "{what}: {}", stderr(&o));
    };
    damage("times");
    damage("points");
    damage("completed");
    let _ = Command::new("true").status();
}

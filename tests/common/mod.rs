//! Helpers shared by the integration tests: running scenes, collecting errors, fitting rates.
#![allow(dead_code)]

use tresca_cr::{Problem, Scene, StepResult};

/// Read a scene from the repository.
pub fn scene(path: &str) -> Scene {
    Scene::from_file(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path).as_path())
        .unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// Run a scene and keep every step.
pub fn run(scene: Scene) -> (Problem, Vec<StepResult>) {
    let p = Problem::new(scene).unwrap();
    let mut out = Vec::new();
    p.run(tresca_cr::RunOptions::all(), |r| {
        out.push(r.clone());
        Ok(())
    })
    .unwrap();
    (p, out)
}

/// Max over time nodes of (energy, L²) errors.
pub fn max_errors(steps: &[StepResult]) -> (f64, f64) {
    steps.iter().fold((0.0, 0.0), |(a, b), r| {
        let e = r.errors.expect("scene has an exact solution");
        (a.max(e.energy), b.max(e.l2))
    })
}

#[allow(unused_imports)]
pub use tresca_cr::study::orders::{fitted_order as fitted_rate, successive_orders as successive_rates};

/// Print a convergence table.
pub fn print_table(title: &str, h: &[f64], cols: &[(&str, &[f64])]) {
    println!("\n{title}");
    print!("{:>10}", "h");
    for (name, _) in cols {
        print!(" {:>12} {:>6}", name, "order");
    }
    println!();
    for i in 0..h.len() {
        print!("{:>10.4e}", h[i]);
        for (_, e) in cols {
            let r = if i == 0 {
                "-".to_string()
            } else {
                format!("{:.3}", tresca_cr::study::orders::observed_order(e[i - 1], e[i], h[i - 1], h[i]))
            };
            print!(" {:>12.4e} {:>6}", e[i], r);
        }
        println!();
    }
}

/// Relative max-norm difference of two vectors.
pub fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().chain(b).fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if scale == 0.0 {
        0.0
    } else {
        diff / scale
    }
}

/// Compare two results files dataset by dataset (bitwise), except wall times and the status.
pub fn same_results(a: &std::path::Path, b: &std::path::Path) {
    let (fa, fb) = (hdf5::File::open(a).unwrap(), hdf5::File::open(b).unwrap());
    let mut names = Vec::new();
    fn walk(g: &hdf5::Group, prefix: &str, out: &mut Vec<String>) {
        for m in g.member_names().unwrap() {
            let full = format!("{prefix}/{m}");
            if let Ok(sub) = g.group(&m) {
                walk(&sub, &full, out);
            } else {
                out.push(full);
            }
        }
    }
    walk(&fa.group("/").unwrap(), "", &mut names);
    let mut nb = Vec::new();
    walk(&fb.group("/").unwrap(), "", &mut nb);
    assert_eq!(names, nb, "dataset lists differ");
    for n in names.iter().filter(|n| !n.ends_with("wall_time")) {
        let (da, db) = (fa.dataset(n).unwrap(), fb.dataset(n).unwrap());
        assert_eq!(da.shape(), db.shape(), "{n}");
        let bits = |d: &hdf5::Dataset| -> Vec<u64> {
            use hdf5::types::{FloatSize, TypeDescriptor as T};
            match d.dtype().unwrap().to_descriptor().unwrap() {
                T::Float(FloatSize::U8) => d.read_raw::<f64>().unwrap().iter().map(|f| f.to_bits()).collect(),
                T::Float(FloatSize::U4) => d.read_raw::<f32>().unwrap().iter().map(|f| f.to_bits() as u64).collect(),
                T::Unsigned(_) => d.read_raw::<u8>().unwrap().iter().map(|&f| f as u64).collect(),
                T::Integer(_) => d.read_raw::<i64>().unwrap().iter().map(|&f| f as u64).collect(),
                other => panic!("{n}: unexpected type {other:?}"),
            }
        };
        assert!(bits(&da) == bits(&db), "{n} differs");
    }
    assert_eq!(
        std::fs::read_to_string(tresca_cr::output::sidecar(a))
            .unwrap()
            .replace(&*a.file_name().unwrap().to_string_lossy(), "X"),
        std::fs::read_to_string(tresca_cr::output::sidecar(b))
            .unwrap()
            .replace(&*b.file_name().unwrap().to_string_lossy(), "X")
    );
}

/// The release binary (for tests through the command line).
pub fn bin() -> std::process::Command {
    std::process::Command::new(env!("CARGO_BIN_EXE_tresca-cr"))
}

/// The temporary directories of this test process, removed when it exits ([`tmp_in`]).
static TMP_DIRS: std::sync::Mutex<Vec<std::path::PathBuf>> = std::sync::Mutex::new(Vec::new());

extern "C" fn remove_tmp_dirs() {
    if std::env::var_os("TRESCA_KEEP_TMP").is_none() {
        for d in TMP_DIRS.lock().map(|v| v.clone()).unwrap_or_default() {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

/// `name` in a temporary directory of this test process, `prefix-<pid>`. The directory is removed when
/// the process exits (each `cargo test` used to leave about 400 MB behind, the CLI tests' 90 MB and the
/// fault tests' 290 MB among them); set `TRESCA_KEEP_TMP` to keep it.
pub fn tmp_in(prefix: &str, name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("{prefix}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let mut dirs = TMP_DIRS.lock().unwrap_or_else(|e| e.into_inner());
    if !dirs.contains(&d) {
        if dirs.is_empty() {
            // SAFETY: registers a plain function, run by the C library at process exit (the test harness
            // ends with `exit` or by returning from main)
            unsafe { libc::atexit(remove_tmp_dirs) };
        }
        dirs.push(d.clone());
    }
    d.join(name)
}

/// A path of the repository as a string.
pub fn root(p: &str) -> String {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(p).display().to_string()
}

/// Standard error of a finished command.
pub fn stderr(o: &std::process::Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Held while this process has an HDF5 file open and while it starts a child: HDF5 opens files without
/// O_CLOEXEC and locks them, so a child forked by another test thread meanwhile would inherit the
/// descriptor, and its lock, for its whole life (a `--resume` then fails with "unable to lock file").
pub static FORK: std::sync::Mutex<()> = std::sync::Mutex::new(());

pub fn fork_guard() -> std::sync::MutexGuard<'static, ()> {
    FORK.lock().unwrap_or_else(|e| e.into_inner())
}

/// Start `cmd` (stdout and stderr piped) under [`FORK`].
pub fn spawn(cmd: &mut std::process::Command) -> std::process::Child {
    let _g = fork_guard();
    cmd.stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap()
}

/// Peak resident memory of the release binary run with `args`, bytes: the child's own `ru_maxrss` (wait4),
/// so tests running beside it do not count. Panics unless it exits 0.
pub fn peak_rss(args: &[&str]) -> u64 {
    // reaped below by wait4, which reports the child's own peak (std's wait does not)
    let child = {
        let _g = fork_guard();
        bin().args(args).stdout(std::process::Stdio::null()).spawn().unwrap().id() as libc::pid_t
    };
    let (mut status, mut usage) = (0, unsafe { std::mem::zeroed::<libc::rusage>() });
    // SAFETY: waits for our own child, filling the status and rusage given.
    let pid = unsafe { libc::wait4(child, &mut status, 0, &mut usage) };
    assert_eq!(pid, child);
    assert!(libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0, "{args:?} failed: {status}");
    usage.ru_maxrss as u64 * 1024
}

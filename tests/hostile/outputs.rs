//! Hostile outputs of issue 43 §1: every file a command writes (`--json` and its `FILE.tmp`, `--csv`,
//! `study --differences`' files, `adapt --out`'s level files and `--gmsh` meshes) under the results
//! file's rule (`src/output/guard.rs`). Each command runs under a deadline and is killed past it, so that
//! one which opens a FIFO fails the test instead of hanging it (the deadline bounds a hang, it is no
//! requirement on time).

use super::{base, s, tmp};
use crate::common::{bin, root, spawn, stderr};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

/// Longer than any of these commands takes when it is refused or runs (a few seconds at most).
const DEADLINE: Duration = Duration::from_secs(120);

/// Run the binary with `args`; killed (and the test failed) if it has not ended by [`DEADLINE`].
fn within(args: &[&str]) -> Output {
    let mut child = spawn(bin().args(args));
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} did not end within {DEADLINE:?}: it blocked (on a FIFO?)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// A file holding "V\n" that no command may change.
fn victim(name: &str) -> PathBuf {
    let v = tmp(&format!("victim_{name}"));
    std::fs::write(&v, b"V\n").unwrap();
    v
}

fn fresh(p: &Path) {
    let _ = std::fs::remove_file(p);
}

/// The command was refused (exit 1) naming `want`, without running (nothing on standard output).
fn refused(o: &Output, what: &str, want: &str) {
    assert_eq!(o.status.code(), Some(1), "{what}: {}", stderr(o));
    assert!(stderr(o).contains(want), "{what}: want {want:?} in: {}", stderr(o));
    assert!(!stderr(o).contains("panicked"), "{what}: {}", stderr(o));
    assert!(o.stdout.is_empty(), "{what}: it ran: {}", String::from_utf8_lossy(&o.stdout));
}

fn mkfifo(p: &Path) {
    fresh(p);
    let c = std::ffi::CString::new(s(p)).unwrap();
    // SAFETY: mkfifo on a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o644) }, 0);
}

/// A character device (1, 3: the null device) at `p`, where mknod is allowed (never /dev/null itself,
/// which a failing command would replace).
fn mkdev(p: &Path) -> bool {
    fresh(p);
    let c = std::ffi::CString::new(s(p)).unwrap();
    // SAFETY: mknod of a character device on a NUL-terminated path.
    unsafe { libc::mknod(c.as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) == 0 }
}

/// The arguments of `cmd` on `scene` writing the output `flag` (`--json`, `--csv`) to `path`.
fn writing(cmd: &str, scene: &str, flag: &str, path: &str, force: bool) -> Vec<String> {
    let mut a: Vec<&str> = match cmd {
        "check" => vec!["check", scene],
        "run" => vec!["run", scene, "-q"],
        "study" => vec!["study", scene, "--levels", "0:4,1:8"],
        "plan" => vec!["plan", scene, "--target", "1e-2", "--pilot-budget", "5s"],
        _ => vec!["adapt", scene, "--levels", "2"],
    };
    a.extend([flag, path]);
    if force {
        a.push("--force");
    }
    a.into_iter().map(String::from).collect()
}

fn within_owned(args: &[String]) -> Output {
    within(&args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// §1: the system shall never write `--json FILE`'s temporary `FILE.tmp` through a planted symbolic link,
/// in any of the five commands: refused by name before any work, the link's target unchanged.
#[test]
fn json_temporaries_through_planted_links_are_refused() {
    let scene = base();
    for cmd in ["check", "run", "study", "plan", "adapt"] {
        let json = tmp(&format!("planted_{cmd}.json"));
        fresh(&json);
        let link = PathBuf::from(format!("{}.tmp", json.display()));
        fresh(&link);
        let v = victim(&format!("tmp_{cmd}"));
        std::os::unix::fs::symlink(&v, &link).unwrap();
        let o = within_owned(&writing(cmd, &scene, "--json", s(&json), false));
        refused(&o, cmd, "symbolic link");
        assert_eq!(std::fs::read(&v).unwrap(), b"V\n", "{cmd}: written through the link");
        assert!(!json.exists(), "{cmd}: a summary was written");
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "{cmd}");
    }
}

/// §1: the system shall refuse a FIFO, a character device or a file with another hard link as `--json`
/// or `--csv` of every command, even with `--force`, at once (a FIFO is never opened, so nothing blocks)
/// and naming what the path is, leaving it as it was.
#[test]
fn fifos_devices_and_hard_links_as_outputs_are_refused_at_once() {
    let scene = base();
    let outputs = [("run", "--json"), ("check", "--json"), ("study", "--csv"), ("plan", "--csv"), ("adapt", "--csv")];
    for (cmd, flag) in outputs {
        let what = format!("{cmd} {flag}");
        let fifo = tmp(&format!("fifo_{cmd}.out"));
        mkfifo(&fifo);
        refused(&within_owned(&writing(cmd, &scene, flag, s(&fifo), true)), &what, "FIFO");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "{what}: the FIFO was replaced");
        let dev = tmp(&format!("dev_{cmd}.out"));
        if mkdev(&dev) {
            refused(&within_owned(&writing(cmd, &scene, flag, s(&dev), true)), &what, "character device");
            assert!(std::fs::symlink_metadata(&dev).unwrap().file_type().is_char_device(), "{what}: replaced");
        }
        let v = victim(&format!("hard_{cmd}"));
        let hard = tmp(&format!("hard_{cmd}.out"));
        fresh(&hard);
        std::fs::hard_link(&v, &hard).unwrap();
        refused(&within_owned(&writing(cmd, &scene, flag, s(&hard), true)), &what, "2 hard links");
        assert_eq!(std::fs::read(&v).unwrap(), b"V\n", "{what}");
    }
}

/// The L-shape scene of `tests/adapt.rs` (2 steps) in a directory of its own, its Gmsh mesh beside it
/// under the name `mesh`; returns (scene, mesh).
fn lshape_in(dir: &str, mesh: &str) -> (String, PathBuf) {
    let d = tmp(dir);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    let text = std::fs::read_to_string(root("verification/cases/lshape_adapt.toml")).unwrap();
    let text = text.replace("file = \"lshape.msh\"", &format!("file = \"{mesh}\"")).replace("steps = 8", "steps = 2");
    let scene = d.join("lshape.toml");
    std::fs::write(&scene, text).unwrap();
    std::fs::copy(root("verification/cases/lshape.msh"), d.join(mesh)).unwrap();
    (scene.display().to_string(), d.join(mesh))
}

/// §1: the system shall never let `--json`, `--csv` or `adapt --out`'s level files be the scene, its
/// mesh, the results file, its sidecar or lock, a level file or each other, compared by inode (a hard
/// link to the scene counts): refused before any work, every file as it was.
#[test]
fn outputs_that_are_inputs_or_each_other_are_refused() {
    let (scene, mesh) = lshape_in("same", "lshape.msh");
    let dir = Path::new(&mesh).parent().unwrap().to_path_buf();
    let (r, side, lock) = (dir.join("r.h5"), dir.join("r.xdmf"), dir.join("r.h5.lock"));
    let alias = dir.join("alias.toml");
    std::fs::hard_link(&scene, &alias).unwrap();
    let (csv, levels) = (dir.join("x.csv"), dir.join("levels"));
    std::fs::create_dir_all(&levels).unwrap();
    let at = |k: &str| levels.join(k).display().to_string();
    let (l1, x0, m7) = (at("level_1.h5"), at("level_0.xdmf"), at("level_7.msh"));
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["run", &scene, "-q", "--force", "--json", &scene], "overwrite the run's input"),
        (vec!["run", &scene, "-q", "--force", "--json", s(&mesh)], "overwrite the run's input"),
        (vec!["run", &scene, "-q", "--force", "--json", s(&alias)], "overwrite the run's input"),
        (vec!["study", &scene, "--levels", "0:2,1:2", "--force", "--csv", s(&mesh)], "overwrite the run's input"),
        (vec!["plan", &scene, "--target", "1e-2", "--force", "--json", s(&alias)], "overwrite the run's input"),
        (vec!["adapt", &scene, "--levels", "2", "--force", "--csv", &scene], "overwrite the run's input"),
        (vec!["run", &scene, "-q", "-o", s(&r), "--json", s(&r)], "same file"),
        (vec!["run", &scene, "-q", "-o", s(&r), "--json", s(&side)], "same file"),
        (vec!["run", &scene, "-q", "-o", s(&r), "--json", s(&lock)], "same file"),
        (vec!["study", &scene, "--levels", "0:2,1:2", "--csv", s(&csv), "--json", s(&csv)], "same file"),
        (vec!["adapt", &scene, "--levels", "2", "--out", s(&levels), "--csv", &l1], "same file"),
        (vec!["adapt", &scene, "--levels", "2", "--out", s(&levels), "--json", &x0], "same file"),
        (vec!["adapt", &scene, "--target", "1e-9", "--out", s(&levels), "--gmsh", "--csv", &m7], "same file"),
    ];
    let before = [std::fs::read(&scene).unwrap(), std::fs::read(&mesh).unwrap()];
    for (args, want) in &cases {
        refused(&within(args), &format!("{args:?}"), want);
        assert_eq!([std::fs::read(&scene).unwrap(), std::fs::read(&mesh).unwrap()], before, "{args:?}");
        assert!(!r.exists() && !csv.exists() && !levels.join("level_0.h5").exists(), "{args:?}: wrote");
    }
    // adapt --out where the scene's own mesh is a level's mesh name: refused, the mesh kept
    let (scene, mesh) = lshape_in("own_level", "level_0.msh");
    let before = std::fs::read(&mesh).unwrap();
    let dir = mesh.parent().unwrap().display().to_string();
    let o = within(&["adapt", &scene, "--levels", "2", "--out", &dir, "--gmsh", "--force"]);
    refused(&o, "adapt --out onto the mesh", "overwrite the run's input");
    assert_eq!(std::fs::read(&mesh).unwrap(), before);
}

/// §1: the system shall not write `--gmsh`'s level meshes, `adapt --out`'s level files or `--differences`'
/// files through a symbolic link planted under their names, nor open a FIFO there (it would block),
/// refusing before the first level, and shall refuse a `--differences` path that is not a directory.
#[test]
fn links_and_fifos_under_level_and_difference_names_are_refused_before_any_level() {
    let scene = base();
    for (kind, want) in [("link", "symbolic link"), ("fifo", "FIFO")] {
        let plant = |p: &Path, v: &Path| match kind {
            "link" => std::os::unix::fs::symlink(v, p).unwrap(),
            _ => mkfifo(p),
        };
        for name in ["level_1.msh", "level_1.h5", "level_1.xdmf"] {
            let levels = tmp(&format!("planted_levels_{kind}"));
            let _ = std::fs::remove_dir_all(&levels);
            std::fs::create_dir_all(&levels).unwrap();
            let v = victim(&format!("levels_{kind}"));
            plant(&levels.join(name), &v);
            let o = within(&["adapt", &scene, "--levels", "2", "--out", s(&levels), "--gmsh", "--force"]);
            refused(&o, &format!("--out with {kind} {name}"), want);
            assert_eq!(std::fs::read(&v).unwrap(), b"V\n");
            assert!(!levels.join("level_0.h5").exists() && !levels.join("level_0.msh").exists(), "level 0 written");
        }
        let diffs = tmp(&format!("planted_diffs_{kind}"));
        let _ = std::fs::remove_dir_all(&diffs);
        std::fs::create_dir_all(&diffs).unwrap();
        let v = victim(&format!("diffs_{kind}"));
        plant(&diffs.join("difference_2_16.xdmf"), &v);
        let o = within(&["study", &scene, "--levels", "0:4,1:8,2:16", "--differences", s(&diffs), "--force"]);
        refused(&o, &format!("--differences with {kind}"), want);
        assert_eq!(std::fs::read(&v).unwrap(), b"V\n");
        assert!(!diffs.join("difference_1_8.xdmf").exists(), "a level's file was written");
    }
    let file = victim("diffs_file");
    let o = within(&["study", &scene, "--levels", "0:4,1:8", "--differences", s(&file)]);
    refused(&o, "--differences FILE", "not a directory");
    assert_eq!(std::fs::read(&file).unwrap(), b"V\n");
}

/// §1: the system shall replace an existing output only with `--force`, and a command refused for one
/// of its outputs shall leave every other as it was: an `adapt --gmsh` whose level file exists keeps
/// the `.msh` beside it.
#[test]
fn existing_outputs_are_replaced_only_with_force_and_never_by_a_refused_command() {
    let scene = base();
    let levels = tmp("kept_levels");
    let _ = std::fs::remove_dir_all(&levels);
    let args = ["adapt", &scene, "--levels", "1", "--out", s(&levels), "--gmsh"];
    let o = within(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let msh = levels.join("level_0.msh");
    std::fs::write(&msh, b"MINE\n").unwrap();
    let h5 = std::fs::read(levels.join("level_0.h5")).unwrap();
    refused(&within(&args), "adapt again", "--force");
    assert_eq!(std::fs::read(&msh).unwrap(), b"MINE\n", "the refused run overwrote the .msh");
    assert_eq!(std::fs::read(levels.join("level_0.h5")).unwrap(), h5);
    let o = within(&[&args[..], &["--force"]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(std::fs::read_to_string(&msh).unwrap().starts_with("$MeshFormat"), "--force replaces it");
    for cmd in ["check", "run", "study", "plan"] {
        let (flag, mine) =
            if matches!(cmd, "study" | "plan") { ("--csv", "mine.csv") } else { ("--json", "mine.json") };
        let out = tmp(&format!("{cmd}_{mine}"));
        std::fs::write(&out, b"MINE\n").unwrap();
        refused(&within_owned(&writing(cmd, &scene, flag, s(&out), false)), cmd, "pass --force");
        assert_eq!(std::fs::read(&out).unwrap(), b"MINE\n", "{cmd}");
        if cmd != "plan" {
            let o = within_owned(&writing(cmd, &scene, flag, s(&out), true));
            assert!(o.status.success(), "{cmd}: {}", stderr(&o));
            assert_ne!(std::fs::read(&out).unwrap(), b"MINE\n", "{cmd}: --force did not replace it");
        }
    }
}

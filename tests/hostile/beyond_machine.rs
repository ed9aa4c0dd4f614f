//! Counts no machine can serve, given where a count is read: `--threads` and `TRESCA_THREADS` (each an OS
//! thread of the pool), `adapt --levels` (each a name to check before the first level) and
//! `adapt --reference` (a mesh to build before its solve was weighed). Each is refused, or stops the loop,
//! naming the limit, without a panic or an allocation beyond the machine.

use super::{base, s, tmp};
use crate::common::{bin, spawn, stderr};
use std::process::Output;

/// `cmd` with its address space limited to 4 GB (a regression allocating beyond the machine fails
/// instead of taking the memory of every other process).
fn limited(args: &[&str], env: Option<(&str, &str)>) -> Output {
    let mut c = bin();
    c.args(args);
    if let Some((k, v)) = env {
        c.env(k, v);
    }
    spawn(super::address_space(&mut c, 4 << 30)).wait_with_output().unwrap()
}

/// The system shall refuse a thread count beyond what a run starts (`threads::MAX`, or the cores if
/// more), from `--threads` or `TRESCA_THREADS`, naming the most it takes, instead of starting 10⁶ threads.
#[test]
fn thread_counts_beyond_any_machine_are_refused() {
    let scene = base();
    for (flag, env) in
        [(Some("18446744073709551615"), None), (Some("4000000"), None), (None, Some(("TRESCA_THREADS", "100000")))]
    {
        let mut args = vec!["check", scene.as_str()];
        args.extend(flag.map(|f| ["--threads", f]).into_iter().flatten());
        let o = limited(&args, env);
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{flag:?} {env:?}: {e}");
        assert!(e.contains("thread count") && e.contains("at most") && !e.contains("panicked"), "{e}");
    }
    let o = limited(&["check", &scene, "--threads", "3"], None);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// The system shall run `adapt --levels` of any size (2⁶⁴ − 1 included) until a level does not fit,
/// checking only the level names that exist, and shall refuse a `--reference` generation whose mesh
/// cannot fit before building it, naming the unknowns it has at least; no level file is left unchecked
/// (a planted link under a later level's name is still refused).
#[test]
fn adapt_levels_and_references_beyond_any_machine_are_refused() {
    let scene = base();
    let dir = tmp("adapt_beyond");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let huge = "18446744073709551615";
    let o = limited(&["adapt", &scene, "--levels", huge, "--out", s(&dir), "--max-memory", "60M"], None);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    assert!(e.contains("does not fit") && !e.contains("panicked"), "{e}");
    assert!(dir.join("level_0.h5").exists() && dir.join("level_1.h5").exists());
    // a link planted under a level's name is still refused, before level 0
    let victim = tmp("adapt_victim");
    std::fs::write(&victim, b"V\n").unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::os::unix::fs::symlink(&victim, dir.join("level_7.h5")).unwrap();
    let o = limited(&["adapt", &scene, "--levels", huge, "--out", s(&dir), "--max-memory", "60M"], None);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("level 7") && stderr(&o).contains("symbolic link"), "{}", stderr(&o));
    assert!(!dir.join("level_0.h5").exists());
    assert_eq!(std::fs::read(&victim).unwrap(), b"V\n");
    // generation 24 over the starting mesh: 2^24 triangles and more per triangle, refused unbuilt
    let o = limited(&["adapt", &scene, "--levels", "2", "--reference", "24"], None);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(3), "{e}");
    assert!(e.contains("reference solve (at least") && e.contains("does not fit"), "{e}");
    assert!(!e.contains("panicked"), "{e}");
}

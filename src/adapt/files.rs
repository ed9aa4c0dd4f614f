//! The names `adapt --out DIR` writes: per level k `DIR/level_<k>.h5` (a results file, with its sidecar
//! `level_<k>.xdmf`) and, with `--gmsh`, `DIR/level_<k>.msh`; and which levels' names a loop may write,
//! so that all of them are checked before its first level ([`crate::output::guard`]).

use std::path::{Path, PathBuf};

/// The results file of level `k`.
pub fn level_results(dir: &Path, k: usize) -> PathBuf {
    dir.join(format!("level_{k}.h5"))
}

/// The Gmsh mesh of level `k`.
pub fn level_mesh(dir: &Path, k: usize) -> PathBuf {
    dir.join(format!("level_{k}.msh"))
}

/// The level whose file `name` would be (`level_<k>` followed by `.`), if any.
fn level_of(name: &std::ffi::OsStr) -> Option<usize> {
    let rest = name.to_str()?.strip_prefix("level_")?;
    let (k, _) = rest.split_once('.')?;
    (!k.is_empty() && k.bytes().all(|b| b.is_ascii_digit())).then(|| k.parse().ok())?
}

/// The levels whose names a loop of `levels` levels (unbounded: `None`, a loop run to a target) may write
/// in `dir` and that need checking: level 0 (whose names check the directory) and every level below
/// `levels` named by an entry of `dir` or by one of `others` (the command's other paths) in `dir`. A name
/// that is neither passes every check but the directory's, so `--levels 10^19` lists no more than these.
pub fn levels_to_check(dir: &Path, levels: Option<usize>, others: &[&Path]) -> Vec<usize> {
    let named = std::fs::read_dir(dir).into_iter().flatten().flatten().map(|e| e.file_name());
    let beside = others.iter().filter(|p| same_dir(p, dir)).filter_map(|p| p.file_name().map(|n| n.to_owned()));
    let below = |k: &usize| levels.is_none_or(|n| *k < n);
    let mut ks: Vec<usize> =
        std::iter::once(0).chain(named.chain(beside).filter_map(|n| level_of(&n))).filter(below).collect();
    ks.sort_unstable();
    ks.dedup();
    ks
}

/// `path` is an entry of the directory `dir` (compared by (device, inode) where both exist).
fn same_dir(path: &Path, dir: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    let parent = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    match (std::fs::metadata(parent), std::fs::metadata(dir)) {
        (Ok(a), Ok(b)) => (a.dev(), a.ino()) == (b.dev(), b.ino()),
        _ => parent == dir,
    }
}

//! Records the git commit of the build (shown by `tresca-cr --version` and stored in results files).
//!
//! The script reruns when the commit moves (HEAD, its reflog, the branch it names) or a source file changes,
//! never on `.git/index`: `git status` (here, or any tool's) rewrites the index's stat cache, and watching it
//! rebuilt the crate on every `cargo build` after `cargo test`. Paths come from `git rev-parse --git-path`, so
//! a linked worktree (where `.git` is a file) watches its own HEAD instead of a missing `.git/HEAD`.
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let o = Command::new("git").args(args).output().ok().filter(|o| o.status.success())?;
    String::from_utf8(o.stdout).ok().map(|s| s.trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let dirty = git(&["status", "--porcelain", "--untracked-files=no"]).is_some_and(|s| !s.is_empty());
    println!("cargo:rustc-env=TRESCA_BUILD_COMMIT={commit}{}", if dirty { "-dirty" } else { "" });
    // HEAD's reflog moves with every commit, checkout and reset of this worktree (and only of it)
    let branch = git(&["symbolic-ref", "-q", "HEAD"]);
    for name in ["HEAD", "logs/HEAD"].into_iter().chain(branch.as_deref()) {
        if let Some(path) = git(&["rev-parse", "--git-path", name]).filter(|p| std::path::Path::new(p).exists()) {
            println!("cargo:rerun-if-changed={path}");
        }
    }
    for path in ["src", "build.rs", "Cargo.toml", "Cargo.lock"] {
        println!("cargo:rerun-if-changed={path}");
    }
}

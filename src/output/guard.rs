//! The one rule every file a command writes follows (stated in docs/results.md, "Every output, one
//! rule"): the results file and its sidecar, `--json`, `--csv`, `study --differences`' files and
//! `adapt --out`'s level files and `--gmsh` meshes.
//!
//! * [`Outputs::check`], before any work: every output is absent or a regular file with a single link
//!   (a symbolic link, a hard link, a device, a FIFO, a socket or a directory is refused by name, found
//!   with `lstat`, so nothing is opened and a FIFO never blocks); an existing one is replaced only with
//!   `--force`; and no output is the same file as an input (the scene, its mesh) or as another output,
//!   compared by (device, inode), or for a file still to be made by its directory's (device, inode) and
//!   its name.
//! * [`write_new`], when the text is ready: the same checks again, then the text goes into `FILE.tmp`,
//!   created exclusively without following links (`O_CREAT | O_EXCL | O_NOFOLLOW`), which is renamed over
//!   `FILE`: a rename replaces the name, never what a link points to, and a failed write leaves the old
//!   file as it was.

use super::paths::{clear_stale, create_new, lstat, refuse, sidecar};
use crate::error::Result;
use crate::input::kind_of;
use crate::scene::{MeshSpec, Scene};
use std::ffi::OsString;
use std::io::Write;
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// How an output of [`Outputs`] is checked.
#[derive(Clone, Copy, PartialEq)]
enum Rule {
    /// A file the command makes or replaces: absent, or (with `--force`) a regular file with one link.
    New,
    /// The command's own temporary (`FILE.tmp`): absent, or a regular file with one link that a killed
    /// command left (it is removed before the new one is created).
    Scratch,
    /// A name whose writer checks its kind itself (the lock and `.partial` files of a results file, a
    /// results file written in place by `--resume`): only compared with the other names.
    Compared,
}

struct Named {
    path: PathBuf,
    what: String,
    rule: Rule,
}

/// What a name is, for comparing: the (device, inode) of the file there, else (a file still to be made)
/// its directory's (device, inode) and its name, else (the directory too is to be made) the path.
#[derive(PartialEq)]
enum Id {
    File(u64, u64),
    Name(u64, u64, OsString),
    Path(PathBuf),
}

fn id_of(path: &Path, follow: bool) -> Id {
    let meta = if follow { std::fs::metadata(path) } else { std::fs::symlink_metadata(path) };
    if let Ok(m) = meta {
        return Id::File(m.dev(), m.ino());
    }
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    match (std::fs::metadata(dir), path.file_name()) {
        (Ok(d), Some(name)) => Id::Name(d.dev(), d.ino(), name.to_owned()),
        _ => Id::Path(std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf())),
    }
}

/// The inputs and outputs of one command, checked together before any work (module doc).
pub struct Outputs {
    force: bool,
    inputs: Vec<Named>,
    outputs: Vec<Named>,
    dirs: Vec<Named>,
}

impl Outputs {
    /// No names yet; `force`: existing outputs may be replaced.
    pub fn new(force: bool) -> Outputs {
        Outputs { force, inputs: Vec::new(), outputs: Vec::new(), dirs: Vec::new() }
    }

    /// The inputs of `scene`: its file and its Gmsh mesh.
    pub fn inputs_of(mut self, scene: &Scene) -> Outputs {
        self.inputs.push(Named { path: PathBuf::from(&scene.file), what: "scene".into(), rule: Rule::Compared });
        if let MeshSpec::Gmsh { path, .. } = &scene.mesh {
            self.inputs.push(Named { path: path.clone(), what: "mesh".into(), rule: Rule::Compared });
        }
        self
    }

    fn push(&mut self, path: PathBuf, what: String, rule: Rule) {
        self.outputs.push(Named { path, what, rule });
    }

    /// A file written by [`write_new`] (`what` names it in messages, e.g. "--json file"), and its temporary.
    pub fn file(mut self, path: &Path, what: &str) -> Outputs {
        self.push(path.to_path_buf(), what.into(), Rule::New);
        self.push(temporary(path), format!("temporary of the {what}"), Rule::Scratch);
        self
    }

    /// Each of `paths` as [`Outputs::file`].
    pub fn files<'a>(self, paths: impl IntoIterator<Item = &'a Path>, what: &str) -> Outputs {
        paths.into_iter().fold(self, |o, p| o.file(p, what))
    }

    /// A results file (`what`: e.g. "results file", "level file") with its sidecar, lock and `.partial`
    /// files; `in_place`: written into (`--resume`), so only compared.
    pub fn results(mut self, path: &Path, what: &str, in_place: bool) -> Outputs {
        let rule = if in_place { Rule::Compared } else { Rule::New };
        self.push(path.to_path_buf(), what.into(), rule);
        self.push(sidecar(path), format!("XDMF sidecar of the {what}"), rule);
        let suffixed = |p: &Path, s: &str| {
            let mut o = p.as_os_str().to_owned();
            o.push(s);
            PathBuf::from(o)
        };
        for (p, w) in [
            (super::lock_path(path), "lock"),
            (suffixed(path, ".partial"), "partial file"),
            (suffixed(&sidecar(path), ".partial"), "partial sidecar"),
        ] {
            self.push(p, format!("{w} of the {what}"), Rule::Compared);
        }
        self
    }

    /// A directory the command writes into (made when missing): an existing path there must be one (a
    /// symbolic link to a directory included).
    pub fn dirs<'a>(mut self, paths: impl IntoIterator<Item = &'a Path>, what: &str) -> Outputs {
        self.dirs.extend(paths.into_iter().map(|p| Named {
            path: p.to_path_buf(),
            what: what.into(),
            rule: Rule::Compared,
        }));
        self
    }

    /// Refuse, naming the path and the problem, an output that is not a file this command may write or
    /// that is an input or another output (module doc).
    pub fn check(&self) -> Result<()> {
        for d in &self.dirs {
            if let Some(m) = std::fs::metadata(&d.path).ok().filter(|m| !m.is_dir()) {
                let kind = kind_of(m.file_type());
                return Err(refuse(&d.path, format!("the {} is {kind}, not a directory", d.what)));
            }
        }
        self.check_distinct()?;
        for o in &self.outputs {
            match o.rule {
                Rule::New => check_new(&o.path, &o.what, self.force)?,
                Rule::Scratch => check_scratch(&o.path, &o.what)?,
                Rule::Compared => {}
            }
        }
        Ok(())
    }

    /// Refuse an output that is an input or another output (by (device, inode), [`Id`]).
    fn check_distinct(&self) -> Result<()> {
        let ids: Vec<Id> = self.outputs.iter().map(|o| id_of(&o.path, false)).collect();
        for i in &self.inputs {
            let id = id_of(&i.path, true);
            if let Some(o) = ids.iter().position(|o| *o == id).map(|k| &self.outputs[k]) {
                let input = format!("{} {}", i.what, i.path.display());
                let msg = format!("the {} would overwrite the run's input ({input}); choose another path", o.what);
                return Err(refuse(&o.path, msg));
            }
        }
        for (k, id) in ids.iter().enumerate() {
            if let Some(j) = ids[..k].iter().position(|o| o == id) {
                let (a, b) = (&self.outputs[j], &self.outputs[k]);
                let msg = format!(
                    "the {} and the {} ({}) are the same file: one would overwrite the other; give them different paths",
                    b.what,
                    a.what,
                    a.path.display()
                );
                return Err(refuse(&b.path, msg));
            }
        }
        Ok(())
    }
}

/// `path` with `.tmp` appended: where [`write_new`] builds the file.
pub fn temporary(path: &Path) -> PathBuf {
    let mut s = path.as_os_str().to_owned();
    s.push(".tmp");
    PathBuf::from(s)
}

/// Refuse an output `path` that is not absent or a regular file with one link, or that exists when not
/// `force`.
pub fn check_new(path: &Path, what: &str, force: bool) -> Result<()> {
    let Some(m) = lstat(path)? else { return Ok(()) };
    let t = m.file_type();
    if !t.is_file() {
        let hint = if t.is_symlink() { "; give the path the link points to, or remove the link" } else { "" };
        return Err(refuse(
            path,
            format!("the {what} would go here, but the path is {} (not a regular file){hint}", kind_of(t)),
        ));
    }
    if m.nlink() > 1 {
        return Err(refuse(
            path,
            format!(
                "the {what} would go here, but the file there has {} hard links (replacing it would leave the other \
                 names as they are); remove it or give another path",
                m.nlink()
            ),
        ));
    }
    if !force {
        return Err(refuse(path, format!("the {what} already exists; pass --force to replace it")));
    }
    Ok(())
}

/// Refuse a temporary `path` that is there and is not a regular file with one link.
fn check_scratch(path: &Path, what: &str) -> Result<()> {
    let Some(m) = lstat(path)? else { return Ok(()) };
    let t = m.file_type();
    if !t.is_file() || m.nlink() > 1 {
        let links = if t.is_file() { format!(" with {} hard links", m.nlink()) } else { String::new() };
        return Err(refuse(
            path,
            format!(
                "the {what} would be created here, but the path is {}{links} (not one this program left); remove it",
                kind_of(t)
            ),
        ));
    }
    Ok(())
}

/// Write `bytes` as the new file `path` (`what` names it in messages), replacing an existing one only when
/// `force`: built in `FILE.tmp`, created exclusively, then renamed over `path` (module doc).
pub fn write_new(path: &Path, what: &str, bytes: &[u8], force: bool) -> Result<()> {
    check_new(path, what, force)?;
    let tmp = temporary(path);
    clear_stale(&tmp, &format!("temporary of the {what}"))?;
    let err = |e: std::io::Error| refuse(path, format!("cannot write the {what}: {e}"));
    let written = create_new(&tmp).and_then(|mut f| f.write_all(bytes));
    let moved = written.and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = moved {
        let _ = std::fs::remove_file(&tmp);
        return Err(err(e));
    }
    Ok(())
}

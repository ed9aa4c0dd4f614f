//! The XDMF3 sidecar `run.xdmf` next to `run.h5`: two Temporal collections, `contact` (the Γ_C line
//! cells, when Γ_C exists) and `body` (the triangles), of Uniform grids whose HDF DataItems reference
//! datasets of `run.h5`, so no array is stored twice. ParaView's three XDMF readers (`XDMFReader`,
//! `Xdmf3ReaderS`, `Xdmf3ReaderT`, 5.11) show the pair as a two-block dataset with one time axis, each
//! block with only its own fields; meshio's `xdmf.TimeSeriesReader` reads the *last* temporal collection
//! of a domain, hence `body` comes last.
//!
//! Readers such as meshio read a DataItem as a whole dataset (no hyperslabs), so each frame's arrays are
//! exposed as HDF5 *virtual datasets* `/xdmf/<block>/<array>/<f>` mapping rows f·B … (f+1)·B−1 (frame f) of
//! the flattened VTKHDF arrays of the block (B = its points or cells). Static: `/xdmf/body/topology`
//! (T, 3), `/xdmf/contact/topology` (C, 2), geometry `/VTKHDF/<block>/Points`. Every grid repeats
//! Topology and Geometry (same datasets). Strain and stress are 6-component (xx, yy, zz, xy, yz, xz) and
//! declared `Matrix` so no reader reorders them as XDMF `Tensor6`.
//!
//! The virtual datasets of every frame of the run are created with the file, so committing a frame
//! changes no HDF5 metadata (see `super::h5::Series`); those of frames not yet written map rows that hold
//! no data yet, and a stopped run drops them ([`Xdmf::drop_frames_from`]). The text holds, in each
//! collection, one fixed-size *slot* per frame of the run, blank (whitespace, which XML ignores) until the
//! frame's grid is put into it after the HDF5 step is flushed ([`Xdmf::append_text`]); each commit then
//! replaces the sidecar whole (written into a spare `run.xdmf.partial`, whose name is exchanged with
//! `run.xdmf`, [`Xdmf::write_text`]), so the blocks gain a frame together, and it never names data the
//! file does not hold. A killed run leaves the spare (the previous text) beside the pair; the next run on
//! the path replaces it, and a finished one removes it.
//!
//! The text is started under `run.xdmf.partial` and moved into place by [`Xdmf::publish`] only once
//! `run.h5` is in place (after its own rename on create, after the flush on resume): a run killed while
//! it builds a new file therefore leaves the old pair `run.h5` + `run.xdmf` as they were. (Found by
//! `verification/interrupted_runs.py` on CI: truncating `run.xdmf` at creation, before the HDF5 rename,
//! left a complete old `run.h5` beside an empty collection that meshio refuses.)
//!
//! The HDF5 file is referenced by its bare name, relative to the XDMF file. ParaView 5.11's Xdmf3
//! readers resolve it wrongly when the XDMF file itself is opened by a bare relative name (`run.xdmf`
//! becomes a search for `run.xdmfrun.h5` and pvpython aborts); `./run.h5` fails the same way and an
//! absolute name would break moved files, so `scripts/paraview_view.py` opens files by absolute path.

use super::fields::Fields;
use super::h5::{put, rows};
use super::paths::sidecar;
use super::vtkhdf::{contact_cells, is_byte, BODY_CELLS};
use hdf5::{File, Group};
use std::io::Write;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

const HEAD: &str = "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n";
const TAIL: &str = "  </Domain>\n</Xdmf>\n";

/// Sizes of the two blocks: body points (3T) and triangles, contact points (2C) and edges.
#[derive(Clone, Copy)]
struct Sizes {
    np: usize,
    nt: usize,
    cp: usize,
    nc: usize,
}

/// One array exposed per frame.
struct Array {
    block: &'static str,
    name: &'static str,
    /// Rows per frame and components.
    rows: usize,
    comps: usize,
    /// u8 (`stick_slip`, `status`) or f32.
    byte: bool,
    node: bool,
}

/// Which blocks a file has: Γ_C (the contact block) and its normal unknowns (the normal condition's arrays).
pub type Blocks = (bool, bool);

/// Arrays exposed per frame, body first.
fn arrays(z: Sizes, (contact, normal): Blocks) -> Vec<Array> {
    let mut v = vec![Array { block: "body", name: "displacement", rows: z.np, comps: 3, byte: false, node: true }];
    for (name, comps) in BODY_CELLS {
        v.push(Array { block: "body", name, rows: z.nt, comps, byte: false, node: false });
    }
    if contact {
        v.push(Array { block: "contact", name: "displacement", rows: z.cp, comps: 3, byte: false, node: true });
        for &(name, comps) in contact_cells(normal) {
            v.push(Array { block: "contact", name, rows: z.nc, comps, byte: is_byte(name), node: false });
        }
    }
    v
}

/// A temporal collection of the text: where its slots start and how long each is.
struct Section {
    block: &'static str,
    offset: u64,
    slot: usize,
}

pub struct Xdmf {
    pub path: PathBuf,
    /// Where the text is written until [`Xdmf::publish`] moves it to `path`.
    partial: PathBuf,
    h5_name: String,
    /// One group per array of [`arrays`].
    groups: Vec<Group>,
    file: std::fs::File,
    sizes: Sizes,
    contact: Blocks,
    /// Frames of the whole run.
    total_frames: usize,
    sections: Vec<Section>,
    /// The whole text as it is to be on disk ([`Xdmf::append_text`] fills slots, [`Xdmf::write_text`]
    /// writes it).
    text: Vec<u8>,
    /// True once [`Xdmf::publish`] has moved the text to `path`.
    published: bool,
    /// After publishing, the file at `partial` that holds the previous text (see [`Xdmf::write_text`]).
    spare: Option<std::fs::File>,
}

impl Xdmf {
    /// Create `/xdmf` (topologies, per-array groups, the virtual datasets of all `total_frames` frames) in
    /// the HDF5 file and start the text.
    pub fn create(
        h5: &File,
        h5_path: &Path,
        f: &Fields,
        contact: Blocks,
        total_frames: usize,
    ) -> std::io::Result<Xdmf> {
        let z = Sizes { np: f.n_points(), nt: f.n_tris(), cp: f.contact_points.len(), nc: f.n_contact() };
        let mk = || -> hdf5::Result<Group> {
            let g = h5.create_group("xdmf")?;
            let body = g.create_group("body")?;
            put(&body, "topology", &[z.nt, 3], &(0..z.np as i64).collect::<Vec<_>>())?;
            if contact.0 {
                let c = g.create_group("contact")?;
                put(&c, "topology", &[z.nc, 2], &(0..z.cp as i64).collect::<Vec<_>>())?;
            }
            for a in arrays(z, contact) {
                g.create_group(&format!("{}/{}", a.block, a.name))?;
            }
            Ok(g)
        };
        let group = mk().map_err(std::io::Error::other)?;
        let x = Xdmf::start(h5_path, group, z, contact, total_frames)?;
        (0..total_frames).try_for_each(|k| x.add_frame_datasets(k)).map_err(std::io::Error::other)?;
        Ok(x)
    }

    /// Reopen for a resumed run: recreate the virtual datasets a stopped run dropped and rewrite the text
    /// for `frames` ((step, time) of each complete frame).
    pub fn resume(
        h5: &File,
        h5_path: &Path,
        frames: &[(usize, f64)],
        contact: Blocks,
        total_frames: usize,
    ) -> std::io::Result<Xdmf> {
        let get = || -> hdf5::Result<(Group, Sizes)> {
            let n = |p: &str| h5.dataset(p).map(|d| d.shape()[0]);
            let (np, nt) = (n("VTKHDF/body/Points")?, n("VTKHDF/body/Types")?);
            let (cp, nc) = if contact.0 { (n("VTKHDF/contact/Points")?, n("VTKHDF/contact/Types")?) } else { (0, 0) };
            Ok((h5.group("xdmf")?, Sizes { np, nt, cp, nc }))
        };
        let (group, z) = get().map_err(std::io::Error::other)?;
        let mut x = Xdmf::start(h5_path, group, z, contact, total_frames)?;
        let counts = x.groups.iter().map(|g| g.member_names().map(|m| m.len())).collect::<hdf5::Result<Vec<_>>>();
        let present = counts.map_err(std::io::Error::other)?.into_iter().min().unwrap_or(0);
        x.drop_frames_from(present).map_err(std::io::Error::other)?;
        (present..total_frames).try_for_each(|k| x.add_frame_datasets(k)).map_err(std::io::Error::other)?;
        for (f, &(n, t)) in frames.iter().enumerate() {
            x.append_text(f, n, t)?;
        }
        x.write_text()?;
        Ok(x)
    }

    /// Remove the virtual datasets of frames `first`… (a stopped run keeps only its complete frames).
    pub fn drop_frames_from(&self, first: usize) -> hdf5::Result<()> {
        for g in &self.groups {
            for member in g.member_names()? {
                if member.parse::<usize>().map_or(true, |k| k >= first) {
                    g.unlink(&member)?;
                }
            }
        }
        Ok(())
    }

    fn start(
        h5_path: &Path,
        group: Group,
        sizes: Sizes,
        contact: Blocks,
        total_frames: usize,
    ) -> std::io::Result<Xdmf> {
        let path = sidecar(h5_path);
        let partial = super::partial_path(&path);
        let groups = arrays(sizes, contact)
            .iter()
            .map(|a| group.group(&format!("{}/{}", a.block, a.name)))
            .collect::<hdf5::Result<Vec<_>>>()
            .map_err(std::io::Error::other)?;
        let h5_name = h5_path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        super::paths::clear_stale(&partial, "partial XDMF sidecar").map_err(std::io::Error::other)?;
        let file = super::paths::create_new(&partial)?;
        let mut x = Xdmf {
            path,
            partial,
            h5_name,
            groups,
            file,
            sizes,
            contact,
            total_frames,
            sections: Vec::new(),
            text: Vec::new(),
            published: false,
            spare: None,
        };
        // contact first: meshio reads the last collection, which should be the body
        let blocks: &[&'static str] = if contact.0 { &["contact", "body"] } else { &["body"] };
        let mut text = String::from(HEAD);
        for &block in blocks {
            // the longest grid text of this run (widest time, frame and step numbers) plus slack
            let slot = x.grid(block, total_frames.saturating_sub(1), usize::MAX, -1.2345678901234567e-300).len() + 2;
            text += &format!("    <Grid Name=\"{block}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n");
            x.sections.push(Section { block, offset: text.len() as u64, slot });
            let mut blank = " ".repeat(slot - 1);
            blank.push('\n');
            text += &blank.repeat(total_frames);
            text += "    </Grid>\n";
        }
        text += TAIL;
        x.file.write_all(text.as_bytes())?;
        x.text = text.into_bytes();
        Ok(x)
    }

    /// Move the text from `run.xdmf.partial` to `run.xdmf` (atomically replacing an old sidecar).
    pub fn publish(&mut self) -> std::io::Result<()> {
        std::fs::rename(&self.partial, &self.path)?;
        self.published = true;
        Ok(())
    }

    /// Remove an unpublished text (its run committed nothing).
    pub fn discard(&self) {
        let _ = std::fs::remove_file(&self.partial);
    }

    /// Create the virtual datasets of frame n.
    fn add_frame_datasets(&self, n: usize) -> hdf5::Result<()> {
        for (a, g) in arrays(self.sizes, self.contact).iter().zip(&self.groups) {
            let src = format!("/VTKHDF/{}/{}/{}", a.block, if a.node { "PointData" } else { "CellData" }, a.name);
            let rest: Vec<usize> = if a.comps == 1 { vec![] } else { vec![a.comps] };
            // the source's extent at its largest: a selection of all of a smaller extent would become "all"
            let mut src_ext = vec![self.total_frames * a.rows];
            src_ext.extend(&rest);
            let mut shape = vec![a.rows];
            shape.extend(&rest);
            let key = format!("{n:06}");
            let sel = rows(n * a.rows, (n + 1) * a.rows, &rest);
            let all = rows(0, a.rows, &rest);
            if a.byte {
                g.new_dataset::<u8>()
                    .shape(shape.clone())
                    .virtual_map(".", &src, src_ext, sel, shape, all)
                    .create(key.as_str())?;
            } else {
                g.new_dataset::<f32>()
                    .shape(shape.clone())
                    .virtual_map(".", &src, src_ext, sel, shape, all)
                    .create(key.as_str())?;
            }
        }
        Ok(())
    }

    /// The grid of frame f (step n, time t) of `block`.
    fn grid(&self, block: &str, f: usize, n: usize, t: f64) -> String {
        let (h, z) = (&self.h5_name, self.sizes);
        let item = |dims: String, ty: &str, prec: u8, path: &str| {
            format!("<DataItem Dimensions=\"{dims}\" NumberType=\"{ty}\" Precision=\"{prec}\" Format=\"HDF\">{h}:{path}</DataItem>")
        };
        let (np, topo) = if block == "body" {
            (
                z.np,
                format!(
                    "Type=\"Triangle\" NumberOfElements=\"{}\">{}",
                    z.nt,
                    item(format!("{} 3", z.nt), "Int", 8, "/xdmf/body/topology")
                ),
            )
        } else {
            let it = item(format!("{} 2", z.nc), "Int", 8, "/xdmf/contact/topology");
            (z.cp, format!("Type=\"Polyline\" NodesPerElement=\"2\" NumberOfElements=\"{}\">{it}", z.nc))
        };
        let mut s = format!(
            "      <Grid Name=\"step_{n:06}\" GridType=\"Uniform\">\n        <Time Value=\"{t:e}\"/>\n        \
             <Topology {topo}</Topology>\n        <Geometry GeometryType=\"XYZ\">{}</Geometry>\n",
            item(format!("{np} 3"), "Float", 8, &format!("/VTKHDF/{block}/Points")),
        );
        for a in arrays(z, self.contact).iter().filter(|a| a.block == block) {
            let (kind, center) = match (a.node, a.comps) {
                (true, _) => ("Vector", "Node"),
                (_, 1) => ("Scalar", "Cell"),
                _ => ("Matrix", "Cell"),
            };
            let dims = if a.comps == 1 { a.rows.to_string() } else { format!("{} {}", a.rows, a.comps) };
            let (ty, prec) = if a.byte { ("UChar", 1) } else { ("Float", 4) };
            s += &format!(
                "        <Attribute Name=\"{}\" AttributeType=\"{kind}\" Center=\"{center}\">{}</Attribute>\n",
                a.name,
                item(dims, ty, prec, &format!("/xdmf/{block}/{}/{f:06}", a.name))
            );
        }
        s + "      </Grid>"
    }

    /// Put the grids of frame f (step n) into their slots of the text (in memory; [`Xdmf::write_text`]
    /// writes it once the HDF5 file holds the frame).
    pub fn append_text(&mut self, f: usize, n: usize, t: f64) -> std::io::Result<()> {
        for k in 0..self.sections.len() {
            let sec = &self.sections[k];
            let mut s = self.grid(sec.block, f, n, t);
            if s.len() >= sec.slot || f >= self.total_frames {
                return Err(std::io::Error::other(format!("frame {f} does not fit the XDMF text")));
            }
            s += &" ".repeat(sec.slot - 1 - s.len());
            s.push('\n');
            let at = sec.offset as usize + f * sec.slot;
            self.text[at..at + s.len()].copy_from_slice(s.as_bytes());
        }
        Ok(())
    }

    /// Write the text. Once published, the new text is written into a spare file at `run.xdmf.partial`
    /// and the two names are exchanged atomically (`renameat2(RENAME_EXCHANGE)`; a plain rename where the
    /// file system cannot exchange), so a reader, or a run killed at any moment, sees the sidecar before
    /// or after the commit's frames, in every block alike; the spare then holds the previous text and is
    /// rewritten in place next time (no new file per commit, which cost a file creation per commit).
    /// Writing the slots of the blocks in place took
    /// one `pwrite` per block, and a run killed between them (found by `verification/paraview_check.py`)
    /// left a frame in the contact collection without its body grid, which ParaView's Xdmf3 readers show
    /// as a time without the body. Before publishing, the unpublished file is written in place.
    pub fn write_text(&mut self) -> std::io::Result<()> {
        if !self.published {
            return self.file.write_all_at(&self.text, 0);
        }
        let spare = match self.spare.take() {
            Some(f) => f,
            None => super::paths::create_new(&self.partial)?,
        };
        if let Err(e) = spare.write_all_at(&self.text, 0) {
            // kept (and removed by drop), so the next commit writes it again instead of meeting its name
            self.spare = Some(spare);
            return Err(e);
        }
        if exchange(&self.partial, &self.path)? {
            // the names are swapped: `file` now names the previous text at `partial`
            self.spare = Some(std::mem::replace(&mut self.file, spare));
        } else {
            std::fs::rename(&self.partial, &self.path)?;
            self.file = spare;
        }
        Ok(())
    }
}

impl Drop for Xdmf {
    /// A published sidecar leaves no spare behind, an unpublished one (its file was never completed) no
    /// text.
    fn drop(&mut self) {
        if !self.published || self.spare.is_some() {
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

/// Exchange the names `a` and `b` atomically; `Ok(false)` where the file system cannot.
fn exchange(a: &Path, b: &Path) -> std::io::Result<bool> {
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| std::ffi::CString::new(p.as_os_str().as_bytes()).map_err(std::io::Error::other);
    let (ca, cb) = (c(a)?, c(b)?);
    // SAFETY: two NUL-terminated paths relative to the working directory; no memory is shared.
    let rc =
        unsafe { libc::renameat2(libc::AT_FDCWD, ca.as_ptr(), libc::AT_FDCWD, cb.as_ptr(), libc::RENAME_EXCHANGE) };
    if rc == 0 {
        return Ok(true);
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EINVAL) | Some(libc::ENOSYS) | Some(libc::EOPNOTSUPP) => Ok(false),
        _ => Err(e),
    }
}

//! The XDMF3 sidecar `run.xdmf` next to `run.h5`: a Temporal collection of Uniform grids whose HDF
//! DataItems reference datasets of `run.h5`, so no array is stored twice.
//!
//! Readers such as meshio read a DataItem as a whole dataset (no hyperslabs), so each step's arrays are
//! exposed as HDF5 *virtual datasets* `/xdmf/<array>/<f>` mapping rows f·B … (f+1)·B−1 (frame f) of the flattened
//! VTKHDF arrays (B = points or cells). Static: `/xdmf/topology` (XDMF Mixed: `4 a b c` per triangle,
//! `2 2 a b` per Γ_C line cell), geometry `/VTKHDF/Points`, `cell_kind` `/VTKHDF/CellData/cell_kind`.
//! Every grid repeats Topology and Geometry (same datasets). Strain and stress are 6-component
//! (xx, yy, zz, xy, yz, xz) and declared `Matrix` so no reader reorders them as XDMF `Tensor6`.
//!
//! The virtual datasets of every frame of the run are created with the file, so committing a frame
//! changes no HDF5 metadata (see `super::h5::Series`); those of frames not yet written map rows that hold
//! no data yet, and a stopped run drops them ([`Xdmf::drop_frames_from`]). The text is appended per
//! frame after the HDF5 step is flushed (seeking back over the closing tags), and rewritten whole on
//! resume, so it never names data the file does not hold.
//!
//! The text is started under `run.xdmf.partial` and moved into place by [`Xdmf::publish`] only once
//! `run.h5` is in place (after its own rename on create, after the flush on resume): a run killed while
//! it builds a new file therefore leaves the old pair `run.h5` + `run.xdmf` as they were. (Found by
//! `verification/interrupted_runs.py` on CI: truncating `run.xdmf` at creation, before the HDF5 rename,
//! left a complete old `run.h5` beside an empty collection that meshio refuses.)

use super::fields::Fields;
use super::h5::{put, rows};
use super::vtkhdf::cell_arrays;
use hdf5::{File, Group};
use std::io::{Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

const TAIL: &str = "    </Grid>\n  </Domain>\n</Xdmf>\n";

pub struct Xdmf {
    pub path: PathBuf,
    /// Where the text is written until [`Xdmf::publish`] moves it to `path`.
    partial: PathBuf,
    h5_name: String,
    /// One group per array of [`arrays`].
    groups: Vec<Group>,
    file: std::fs::File,
    /// Length of the text without TAIL.
    len: u64,
    np: usize,
    ncell: usize,
    topo_len: usize,
    contact: bool,
    /// Frames of the whole run.
    total_frames: usize,
}

/// The XDMF path of a results file: same stem, extension `xdmf`.
pub fn sidecar(h5: &Path) -> PathBuf {
    h5.with_extension("xdmf")
}

/// Arrays exposed per step: (name, VTKHDF source, rows per step, components, XDMF number type, precision).
fn arrays(np: usize, ncell: usize, contact: bool) -> Vec<(String, String, usize, usize, &'static str, u8)> {
    let mut v = vec![("displacement".to_string(), "/VTKHDF/PointData/displacement".to_string(), np, 3, "Float", 4)];
    for (name, nc) in cell_arrays(contact) {
        let (ty, prec) = if name == "stick_slip" { ("UChar", 1) } else { ("Float", 4) };
        v.push((name.to_string(), format!("/VTKHDF/CellData/{name}"), ncell, nc, ty, prec));
    }
    v
}

impl Xdmf {
    /// Create `/xdmf` (topology, per-array groups, the virtual datasets of all `total_frames` frames) in
    /// the HDF5 file and start the text.
    pub fn create(h5: &File, h5_path: &Path, f: &Fields, contact: bool, total_frames: usize) -> std::io::Result<Xdmf> {
        let mk = || -> hdf5::Result<(Group, usize)> {
            let g = h5.create_group("xdmf")?;
            let mut topo = Vec::with_capacity(4 * f.n_cells());
            for c in 0..f.n_cells() {
                let (a, b) = (f.offsets[c] as usize, f.offsets[c + 1] as usize);
                if f.types[c] == 5 {
                    topo.push(4);
                } else {
                    topo.extend([2, 2]);
                }
                topo.extend_from_slice(&f.connectivity[a..b]);
            }
            put(&g, "topology", &[topo.len()], &topo)?;
            for (name, ..) in arrays(0, 0, contact) {
                g.create_group(&name)?;
            }
            Ok((g, topo.len()))
        };
        let (group, topo_len) = mk().map_err(std::io::Error::other)?;
        let x = Xdmf::start(h5_path, group, f.n_points(), f.n_cells(), topo_len, contact, total_frames)?;
        (0..total_frames).try_for_each(|k| x.add_frame_datasets(k)).map_err(std::io::Error::other)?;
        Ok(x)
    }

    /// Reopen for a resumed run: recreate the virtual datasets a stopped run dropped and rewrite the text
    /// for `frames` ((step, time) of each complete frame).
    pub fn resume(
        h5: &File,
        h5_path: &Path,
        frames: &[(usize, f64)],
        contact: bool,
        total_frames: usize,
    ) -> std::io::Result<Xdmf> {
        let get = || -> hdf5::Result<(Group, usize, usize, usize)> {
            let g = h5.group("xdmf")?;
            let np = h5.dataset("VTKHDF/Points")?.shape()[0];
            let ncell = h5.dataset("VTKHDF/Types")?.shape()[0];
            let topo_len = g.dataset("topology")?.shape()[0];
            Ok((g, np, ncell, topo_len))
        };
        let (group, np, ncell, topo_len) = get().map_err(std::io::Error::other)?;
        let mut x = Xdmf::start(h5_path, group, np, ncell, topo_len, contact, total_frames)?;
        let counts = x.groups.iter().map(|g| g.member_names().map(|m| m.len())).collect::<hdf5::Result<Vec<_>>>();
        let present = counts.map_err(std::io::Error::other)?.into_iter().min().unwrap_or(0);
        x.drop_frames_from(present).map_err(std::io::Error::other)?;
        (present..total_frames).try_for_each(|k| x.add_frame_datasets(k)).map_err(std::io::Error::other)?;
        for (f, &(n, t)) in frames.iter().enumerate() {
            x.append_text(f, n, t)?;
        }
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
        np: usize,
        ncell: usize,
        topo_len: usize,
        contact: bool,
        total_frames: usize,
    ) -> std::io::Result<Xdmf> {
        let path = sidecar(h5_path);
        let partial = super::partial_path(&path);
        let mut file = std::fs::File::create(&partial)?;
        let head = "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n  <Domain>\n    \
                    <Grid Name=\"tresca\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
        file.write_all(head.as_bytes())?;
        file.write_all(TAIL.as_bytes())?;
        let groups = arrays(0, 0, contact)
            .iter()
            .map(|a| group.group(&a.0))
            .collect::<hdf5::Result<Vec<_>>>()
            .map_err(std::io::Error::other)?;
        let h5_name = h5_path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        Ok(Xdmf {
            path,
            partial,
            h5_name,
            groups,
            file,
            len: head.len() as u64,
            np,
            ncell,
            topo_len,
            contact,
            total_frames,
        })
    }

    /// Move the text from `run.xdmf.partial` to `run.xdmf` (atomically replacing an old sidecar); the
    /// open handle follows the rename, so later frames are appended to the published file.
    pub fn publish(&self) -> std::io::Result<()> {
        std::fs::rename(&self.partial, &self.path)
    }

    /// Remove an unpublished text (its run committed nothing).
    pub fn discard(&self) {
        let _ = std::fs::remove_file(&self.partial);
    }

    /// Create the virtual datasets of frame n.
    fn add_frame_datasets(&self, n: usize) -> hdf5::Result<()> {
        for (i, (_, src, block, nc, ty, _)) in arrays(self.np, self.ncell, self.contact).into_iter().enumerate() {
            let rest: Vec<usize> = if nc == 1 { vec![] } else { vec![nc] };
            // the source's extent at its largest: a selection of all of a smaller extent would become "all"
            let mut src_ext = vec![self.total_frames * block];
            src_ext.extend(&rest);
            let mut shape = vec![block];
            shape.extend(&rest);
            let g = &self.groups[i];
            let key = format!("{n:06}");
            let sel = rows(n * block, (n + 1) * block, &rest);
            let all = rows(0, block, &rest);
            if ty == "UChar" {
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

    /// Append the grid of frame f (step n) to the text (after the HDF5 file holds it).
    pub fn append_text(&mut self, f: usize, n: usize, t: f64) -> std::io::Result<()> {
        let h = &self.h5_name;
        let item = |dims: String, ty: &str, prec: u8, path: &str| {
            format!("<DataItem Dimensions=\"{dims}\" NumberType=\"{ty}\" Precision=\"{prec}\" Format=\"HDF\">{h}:{path}</DataItem>")
        };
        let mut s = format!(
            "      <Grid Name=\"step_{n:06}\" GridType=\"Uniform\">\n        <Time Value=\"{t:e}\"/>\n        \
             <Topology Type=\"Mixed\" NumberOfElements=\"{}\">{}</Topology>\n        \
             <Geometry GeometryType=\"XYZ\">{}</Geometry>\n",
            self.ncell,
            item(self.topo_len.to_string(), "Int", 8, "/xdmf/topology"),
            item(format!("{} 3", self.np), "Float", 8, "/VTKHDF/Points"),
        );
        s += &format!(
            "        <Attribute Name=\"cell_kind\" AttributeType=\"Scalar\" Center=\"Cell\">{}</Attribute>\n",
            item(self.ncell.to_string(), "UChar", 1, "/VTKHDF/CellData/cell_kind")
        );
        for (name, _, block, nc, ty, prec) in arrays(self.np, self.ncell, self.contact) {
            let (kind, center) = match (name.as_str(), nc) {
                ("displacement", _) => ("Vector", "Node"),
                (_, 1) => ("Scalar", "Cell"),
                _ => ("Matrix", "Cell"),
            };
            let dims = if nc == 1 { block.to_string() } else { format!("{block} {nc}") };
            s += &format!(
                "        <Attribute Name=\"{name}\" AttributeType=\"{kind}\" Center=\"{center}\">{}</Attribute>\n",
                item(dims, ty, prec, &format!("/xdmf/{name}/{f:06}"))
            );
        }
        s += "      </Grid>\n";
        self.file.seek(SeekFrom::Start(self.len))?;
        self.file.write_all(s.as_bytes())?;
        self.file.write_all(TAIL.as_bytes())?;
        self.len += s.len() as u64;
        Ok(())
    }
}

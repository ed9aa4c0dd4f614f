//! The `/VTKHDF` group: a temporal VTKHDF 2.x `PartitionedDataSetCollection` of two `UnstructuredGrid`
//! blocks (read by VTK ≥ 9.4's `vtkHDFReader`, whose temporal composite support this needs, and ParaView
//! ≥ 5.13), so the body and the contact line Γ_C are separate datasets, each with only its own fields.
//!
//! * `/VTKHDF`: attributes `Version` = [2, 2], `Type` = "PartitionedDataSetCollection" (fixed-length ASCII);
//!   `Assembly/{body, contact}` are soft links to the blocks (groups track creation order, as the spec asks).
//! * `/VTKHDF/body` (`Index` 0): T triangles on the broken mesh of [`super::fields`] (3T points); point data
//!   `displacement` (3T, 3); cell data `strain`, `stress` (T, 6) and `von_mises` (T).
//! * `/VTKHDF/contact` (`Index` 1, only when Γ_C exists): C line cells on 2C points; point data
//!   `displacement` (2C, 3, the body's at the same points); cell data `sigma_t`, `slip`, `slip_increment`
//!   (f32) and `stick_slip` (u8); with normal unknowns (a unilateral or Coulomb part) also `pressure`,
//!   `gap` (f32) and `status` (u8: 0 stick, 1 slip, 2 separated), as `/tresca/contact` holds them.
//! * Per block, static `NumberOfPoints`, `NumberOfCells`, `NumberOfConnectivityIds`, `Points`,
//!   `Connectivity`, `Offsets`, `Types`; per frame f (rows f·B … (f+1)·B−1 of flattened time-space arrays,
//!   f32; frames are the steps n with n % frame_every == 0 and the last step, see [`Frames`]) the arrays above.
//! * Per block `Steps` (the spec has no top-level `Steps` for composites; both blocks hold the same
//!   frames): attribute `NSteps` (complete frames; updated after the data, in the same flush for both
//!   blocks), `Values` (frame times, grown per frame). `PartOffsets`, `NumberOfParts` (1), `PointOffsets`,
//!   `CellOffsets`, `ConnectivityIdOffsets` (0: static geometry), `PointDataOffsets/*` and
//!   `CellDataOffsets/*` (f·B) are written for all frames at creation; readers only use the first `NSteps`.

use super::fields::{Fields, StepFields, TENSOR};
use super::h5::{attr, attr_fixed_ascii, attr_vec, put, Raw, Series};
use super::rows::{append, bytes};
use super::vtkhdf_lists::{block_misfit, cell_offsets, connectivity, frame_offsets};
use hdf5::plist::group_create::LinkCreationOrder;
use hdf5::{Attribute, Dataset, Extent, Extents, File, Group};

/// Cell arrays of the body block with their components (f32).
pub const BODY_CELLS: [(&str, usize); 3] = [("strain", TENSOR), ("stress", TENSOR), ("von_mises", 1)];
/// Cell arrays of the contact block (f32 but `stick_slip`, u8).
pub const CONTACT_CELLS: [(&str, usize); 4] = [("sigma_t", 1), ("slip", 1), ("slip_increment", 1), ("stick_slip", 1)];
/// Cell arrays of the contact block with normal unknowns: [`CONTACT_CELLS`], then the normal condition
/// (f32 but `status`, u8).
pub const CONTACT_NORMAL_CELLS: [(&str, usize); 7] =
    [("sigma_t", 1), ("slip", 1), ("slip_increment", 1), ("stick_slip", 1), ("pressure", 1), ("gap", 1), ("status", 1)];

/// The u8 cell arrays (the others are f32).
pub fn is_byte(name: &str) -> bool {
    matches!(name, "stick_slip" | "status")
}

/// The contact block's cell arrays, with or without the normal condition.
pub fn contact_cells(normal: bool) -> &'static [(&'static str, usize)] {
    if normal {
        &CONTACT_NORMAL_CELLS
    } else {
        &CONTACT_CELLS
    }
}

/// What a block is: its name and index in the collection, its cells (points per cell and VTK cell
/// type) and its cell arrays.
struct BlockKind {
    name: &'static str,
    index: i64,
    per_cell: usize,
    vtk_type: u8,
    arrays: &'static [(&'static str, usize)],
}

/// The body: triangles (VTK type 5).
const BODY: BlockKind = BlockKind { name: "body", index: 0, per_cell: 3, vtk_type: 5, arrays: &BODY_CELLS };
/// The contact line: Γ_C edges as lines (VTK type 3), with the cell arrays of `contact_cells(normal)`.
fn contact_kind(normal: bool) -> BlockKind {
    BlockKind { name: "contact", index: 1, per_cell: 2, vtk_type: 3, arrays: contact_cells(normal) }
}

/// Which steps are visualisation frames: n % every == 0, and the last step N.
#[derive(Clone, Copy, Debug)]
pub struct Frames {
    pub every: usize,
    pub last: usize,
}

impl Frames {
    pub fn is_frame(&self, n: usize) -> bool {
        n.is_multiple_of(self.every) || n == self.last
    }
    /// Number of frames among steps 0..steps.
    pub fn before(&self, steps: usize) -> usize {
        steps.div_ceil(self.every) + usize::from(steps > self.last && !self.last.is_multiple_of(self.every))
    }
    pub fn total(&self) -> usize {
        self.before(self.last + 1)
    }
}

/// Frames buffered for one write.
#[derive(Default)]
pub struct FrameRows {
    pub first: usize,
    pub times: Vec<f64>,
    displacement: Vec<f32>,
    /// Body cell arrays in the order of [`BODY_CELLS`].
    cells: [Vec<f32>; 3],
    contact_displacement: Vec<f32>,
    /// Contact f32 cell arrays in the order of [`CONTACT_CELLS`] (without `stick_slip`).
    contact_cells: [Vec<f32>; 3],
    stick_slip: Vec<u8>,
    /// `pressure`, `gap` (empty without normal unknowns).
    normal_cells: [Vec<f32>; 2],
    status: Vec<u8>,
}

impl FrameRows {
    pub fn push(&mut self, t: f64, s: &StepFields) {
        self.times.push(t);
        append(&mut self.displacement, &s.displacement);
        for (d, v) in self.cells.iter_mut().zip([&s.strain, &s.stress, &s.von_mises]) {
            append(d, v);
        }
        append(&mut self.contact_displacement, &s.contact_displacement);
        for (d, v) in self.contact_cells.iter_mut().zip([&s.sigma_t, &s.slip, &s.slip_increment]) {
            append(d, v);
        }
        append(&mut self.stick_slip, &s.stick_slip);
        for (d, v) in self.normal_cells.iter_mut().zip([&s.pressure, &s.gap]) {
            append(d, v);
        }
        append(&mut self.status, &s.status);
    }
    pub fn count(&self) -> usize {
        self.times.len()
    }
    /// Bytes buffered in the frames' arrays.
    pub fn bytes(&self) -> usize {
        let f32s = [&self.displacement, &self.contact_displacement]
            .into_iter()
            .chain(&self.cells)
            .chain(&self.contact_cells)
            .chain(&self.normal_cells);
        bytes(f32s) + self.stick_slip.len() + self.status.len()
    }
    /// Empty the buffer, keeping its memory; the next frame is frame `first`.
    pub fn reset(&mut self, first: usize) {
        self.first = first;
        self.times.clear();
        let f32s = [&mut self.displacement, &mut self.contact_displacement];
        for v in f32s.into_iter().chain(&mut self.cells).chain(&mut self.contact_cells).chain(&mut self.normal_cells) {
            v.clear();
        }
        self.stick_slip.clear();
        self.status.clear();
    }
}

/// One `UnstructuredGrid` block: its `Steps` group and its time series.
struct Block {
    /// `Steps` attribute `NSteps`, kept open: it is rewritten at every commit.
    nsteps: Attribute,
    /// `Steps/Values`, the one per-frame array whose length must equal `NSteps` at every commit: VTK
    /// 9.7's reader corrupts its heap on a longer one (measured; a killed run's file crashed it). It is
    /// chunked and grown frame by frame, in the same flush as `NSteps`.
    values: Dataset,
    displacement: Series,
    /// In the order of the block's cell array list.
    cells: Vec<Series>,
}

/// A group whose links keep their creation order (the VTKHDF spec asks this of composite groups).
fn ordered_group(parent: &Group, name: &str) -> hdf5::Result<Group> {
    parent.create_group_builder().with_gcpl(|p| p.link_creation_order(LinkCreationOrder::Indexed)).create(name)
}

impl Block {
    /// Create block `kind` of `points` (`kind.per_cell` points a cell) with room for `m` frames.
    fn create(root: &Group, kind: &BlockKind, points: &[[f64; 3]], m: usize) -> hdf5::Result<Block> {
        let BlockKind { name, index, per_cell, vtk_type, arrays } = *kind;
        let g = root.create_group(name)?;
        attr(&g, "Index", index)?;
        attr_vec(&g, "Version", &[2i64, 2])?;
        attr_fixed_ascii::<16>(&g, "Type", "UnstructuredGrid")?;
        let (np, ncell) = (points.len(), points.len() / per_cell);
        put(&g, "NumberOfPoints", &[1], &[np as i64])?;
        put(&g, "NumberOfCells", &[1], &[ncell as i64])?;
        put(&g, "NumberOfConnectivityIds", &[1], &[np as i64])?;
        put(&g, "Points", &[np, 3], points.as_flattened())?;
        put(&g, "Connectivity", &[np], &connectivity(np))?;
        put(&g, "Offsets", &[ncell + 1], &cell_offsets(ncell, per_cell))?;
        put(&g, "Types", &[ncell], &vec![vtk_type; ncell])?;
        let pd = g.create_group("PointData")?;
        let cd = g.create_group("CellData")?;
        let steps = g.create_group("Steps")?;
        attr(&steps, "NSteps", 0i64)?;
        let zeros = vec![0i64; m];
        for name in ["PartOffsets", "PointOffsets", "CellOffsets", "ConnectivityIdOffsets"] {
            put(&steps, name, &[m], &zeros)?;
        }
        put(&steps, "NumberOfParts", &[m], &vec![1i64; m])?;
        put(&steps.create_group("PointDataOffsets")?, "displacement", &[m], &frame_offsets(m, np))?;
        let cdo = steps.create_group("CellDataOffsets")?;
        let mut cells = Vec::new();
        for &(name, nc) in arrays {
            put(&cdo, name, &[m], &frame_offsets(m, ncell))?;
            let rest: &[usize] = if nc == 1 { &[] } else { &[nc] };
            cells.push(if is_byte(name) {
                Series::create::<u8>(&cd, name, ncell, rest, m)?
            } else {
                Series::create::<f32>(&cd, name, ncell, rest, m)?
            });
        }
        Ok(Block {
            nsteps: steps.attr("NSteps")?,
            values: steps
                .new_dataset::<f64>()
                .chunk(1024)
                .shape(Extents::from(Extent::resizable(0)))
                .create("Values")?,
            displacement: Series::create::<f32>(&pd, "displacement", np, &[3], m)?,
            cells,
        })
    }

    /// Open the block of an existing file; a list stored as a scalar, a frame array whose rows are not as
    /// wide as its components, or frame times that cannot grow, is an error naming it (a damaged file), not
    /// a panic, misplaced rows or a file changed before the error.
    fn open(g: &Group, arrays: &[(&str, usize)]) -> hdf5::Result<Block> {
        let rows = |name: &str| {
            let scalar = || hdf5::Error::from(format!("{}/{name}: a scalar, not a list (damaged)", g.name()));
            g.dataset(name)?.shape().first().copied().ok_or_else(scalar)
        };
        let (np, ncell) = (rows("Points")?, rows("Types")?);
        let cd = g.group("CellData")?;
        let cells = arrays.iter().map(|(name, _)| Series::open(&cd, name, ncell)).collect::<hdf5::Result<Vec<_>>>()?;
        let displacement = Series::open(&g.group("PointData")?, "displacement", np)?;
        let widths = arrays.iter().map(|&(_, nc)| if nc == 1 { vec![] } else { vec![nc] });
        for (s, want) in cells.iter().zip(widths).chain([(&displacement, vec![3])]) {
            if s.rest() != want.as_slice() {
                let msg = format!("{}: rows of shape {:?}, not {want:?} (damaged)", s.ds.name(), s.rest());
                return Err(hdf5::Error::from(msg));
            }
        }
        let steps = g.group("Steps")?;
        let values = steps.dataset("Values")?;
        if !values.is_resizable() {
            return Err(hdf5::Error::from(format!(
                "{}: a list of fixed length, not resizable (damaged)",
                values.name()
            )));
        }
        Ok(Block { nsteps: steps.attr("NSteps")?, values, displacement, cells })
    }

    fn write_times(&self, b: &FrameRows) -> hdf5::Result<()> {
        let (f, k) = (b.first, b.count());
        if k > 0 {
            self.values.resize(f + k)?;
            self.values.write_slice(&b.times, f..f + k)?;
        }
        Ok(())
    }

    fn set_frames(&mut self, raw: &Raw, frames: usize, kept: usize) -> hdf5::Result<()> {
        self.values.resize(kept.min(frames))?;
        std::iter::once(&mut self.displacement).chain(&mut self.cells).try_for_each(|s| s.set_steps(raw, frames, kept))
    }
}

pub struct VtkHdf {
    body: Block,
    contact: Option<Block>,
}

impl VtkHdf {
    /// `contact`: Γ_C exists; `normal`: its edges have normal unknowns.
    pub fn create(file: &File, f: &Fields, n_frames: usize, (contact, normal): (bool, bool)) -> hdf5::Result<VtkHdf> {
        let root = ordered_group(file, "VTKHDF")?;
        attr_vec(&root, "Version", &[2i64, 2])?;
        attr_fixed_ascii::<28>(&root, "Type", "PartitionedDataSetCollection")?;
        let assembly = ordered_group(&root, "Assembly")?;
        let body = Block::create(&root, &BODY, &f.points, n_frames)?;
        assembly.link_soft("/VTKHDF/body", "body")?;
        let contact = if contact {
            let b = Block::create(&root, &contact_kind(normal), &f.contact_points, n_frames)?;
            assembly.link_soft("/VTKHDF/contact", "contact")?;
            Some(b)
        } else {
            None
        };
        Ok(VtkHdf { body, contact })
    }

    pub fn open(file: &File, (contact, normal): (bool, bool)) -> hdf5::Result<VtkHdf> {
        let root = file.group("VTKHDF")?;
        let body = Block::open(&root.group("body")?, &BODY_CELLS)?;
        let contact = if contact { Some(Block::open(&root.group("contact")?, contact_cells(normal))?) } else { None };
        Ok(VtkHdf { body, contact })
    }

    /// The first list of the view in `file` that `--resume` keeps as it is but that is not the one of a run
    /// with these `fields`, Γ_C and normal unknowns (`contact`), `frames` frames in all and the frame
    /// times `kept` committed (`super::vtkhdf_lists`); `None` if all are.
    pub fn misfit(
        file: &File,
        f: &Fields,
        (contact, normal): (bool, bool),
        frames: usize,
        kept: &[f64],
    ) -> Option<String> {
        let contact = contact.then(|| (contact_kind(normal), &f.contact_points));
        std::iter::once((BODY, &f.points)).chain(contact).find_map(|(kind, points)| {
            match file.group(&format!("VTKHDF/{}", kind.name)) {
                Ok(g) => block_misfit(&g, (kind.per_cell, kind.vtk_type, kind.arrays), points, frames, kept),
                Err(_) => Some(format!("VTKHDF/{} is missing", kind.name)),
            }
        })
    }

    /// The frames every frame array has room for (the least).
    pub fn room(&self) -> usize {
        let series =
            std::iter::once(&self.body).chain(&self.contact).flat_map(|b| b.cells.iter().chain([&b.displacement]));
        series.map(Series::capacity).min().unwrap_or(0)
    }

    /// Append buffered frames (NSteps is not changed).
    pub fn write_frames(&self, raw: &Raw, b: &FrameRows) -> hdf5::Result<()> {
        let (f, k) = (b.first, b.count());
        self.body.write_times(b)?;
        self.body.displacement.write_steps(raw, f, k, &b.displacement)?;
        for (series, data) in self.body.cells.iter().zip(&b.cells) {
            series.write_steps(raw, f, k, data)?;
        }
        if let Some(c) = &self.contact {
            c.write_times(b)?;
            c.displacement.write_steps(raw, f, k, &b.contact_displacement)?;
            for (series, data) in c.cells.iter().zip(&b.contact_cells) {
                series.write_steps(raw, f, k, data)?;
            }
            c.cells[3].write_steps(raw, f, k, &b.stick_slip)?;
            if c.cells.len() == CONTACT_NORMAL_CELLS.len() {
                c.cells[4].write_steps(raw, f, k, &b.normal_cells[0])?;
                c.cells[5].write_steps(raw, f, k, &b.normal_cells[1])?;
                c.cells[6].write_steps(raw, f, k, &b.status)?;
            }
        }
        Ok(())
    }

    /// Set `NSteps` of every block (they always hold the same frames).
    pub fn set_nsteps(&self, n: usize) -> hdf5::Result<()> {
        std::iter::once(&self.body).chain(&self.contact).try_for_each(|b| b.nsteps.write_scalar(&(n as i64)))
    }

    /// Give every frame series room for exactly `frames` frames, keeping the first `kept`; `Values`
    /// holds exactly the kept frames.
    pub fn set_frames(&mut self, raw: &Raw, frames: usize, kept: usize) -> hdf5::Result<()> {
        std::iter::once(&mut self.body).chain(&mut self.contact).try_for_each(|b| b.set_frames(raw, frames, kept))
    }
}

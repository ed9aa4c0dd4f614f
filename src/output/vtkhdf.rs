//! The `/VTKHDF` group: a temporal VTKHDF 2.x `UnstructuredGrid` (read by VTK ≥ 9.3's `vtkHDFReader`
//! and ParaView ≥ 5.13) with a static mesh written once.
//!
//! * Attributes `Version` = [2, 2], `Type` = "UnstructuredGrid" (fixed-length ASCII).
//! * Static: `NumberOfPoints` [3T], `NumberOfCells` [T + C], `NumberOfConnectivityIds`, `Points` (3T, 3),
//!   `Connectivity`, `Offsets`, `Types` (5 triangle, 3 line); the broken mesh of [`super::fields`].
//!   `CellData/cell_kind` (0 triangle, 1 Γ_C edge) is static too (its offsets are all 0).
//! * Per frame f (rows f·P … (f+1)·P−1 of a flattened time-space array, f32; frames are the steps
//!   n with n % frame_every == 0 and the last step, see [`Frames`]): `PointData/displacement`
//!   (P, 3); `CellData/{strain, stress}` (T + C, 6), `CellData/von_mises`, and with Γ_C
//!   `CellData/{sigma_t, slip, slip_increment}` (f32) and `CellData/stick_slip` (u8).
//! * `Steps`: attribute `NSteps` (complete frames; updated after the data), `Values` (frame times, grown
//!   per frame). `PartOffsets`, `NumberOfParts` (1), `PointOffsets`, `CellOffsets`, `ConnectivityIdOffsets` (0: the
//!   geometry is shared by every frame), `PointDataOffsets/*` and `CellDataOffsets/*` (f·P, f·(T+C)) are
//!   written for all frames at creation; readers only use the first `NSteps` entries.

use super::fields::{Fields, StepFields, TENSOR};
use super::h5::{attr, attr_fixed_ascii, attr_vec, put, Raw, Series};
use hdf5::{Dataset, Extent, Extents, File, Group};

/// Names of the per-step cell arrays with their components (all f32 but `stick_slip`).
pub fn cell_arrays(contact: bool) -> Vec<(&'static str, usize)> {
    let mut v = vec![("strain", TENSOR), ("stress", TENSOR), ("von_mises", 1)];
    if contact {
        v.extend([("sigma_t", 1), ("slip", 1), ("slip_increment", 1), ("stick_slip", 1)]);
    }
    v
}

/// Which steps are visualisation frames: n % every == 0, and the last step N.
#[derive(Clone, Copy, Debug)]
pub struct Frames {
    pub every: usize,
    pub last: usize,
}

impl Frames {
    pub fn is_frame(&self, n: usize) -> bool {
        n % self.every == 0 || n == self.last
    }
    /// Number of frames among steps 0..steps.
    pub fn before(&self, steps: usize) -> usize {
        steps.div_ceil(self.every) + usize::from(steps > self.last && self.last % self.every != 0)
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
    /// f32 cell arrays in the order of [`cell_arrays`] (without `stick_slip`).
    cells: [Vec<f32>; 6],
    stick_slip: Vec<u8>,
}

impl FrameRows {
    pub fn push(&mut self, t: f64, s: &StepFields) {
        self.times.push(t);
        self.displacement.extend_from_slice(&s.displacement);
        let src = [&s.strain, &s.stress, &s.von_mises, &s.sigma_t, &s.slip, &s.slip_increment];
        for (d, v) in self.cells.iter_mut().zip(src) {
            d.extend_from_slice(v);
        }
        self.stick_slip.extend_from_slice(&s.stick_slip);
    }
    pub fn count(&self) -> usize {
        self.times.len()
    }
    pub fn reset(&mut self, first: usize) {
        *self = FrameRows { first, ..Default::default() };
    }
}

pub struct VtkHdf {
    steps: Group,
    /// `Steps/Values`, the one per-frame array whose length must equal `NSteps` at every commit: VTK
    /// 9.7's reader corrupts its heap on a longer one (measured; a killed run's file crashed it). It is
    /// chunked and grown frame by frame, in the same flush as `NSteps`.
    values: Dataset,
    displacement: Series,
    /// In the order of [`cell_arrays`].
    cells: Vec<Series>,
}

impl VtkHdf {
    pub fn create(file: &File, f: &Fields, n_frames: usize, contact: bool) -> hdf5::Result<VtkHdf> {
        let root = file.create_group("VTKHDF")?;
        attr_vec(&root, "Version", &[2i64, 2])?;
        attr_fixed_ascii::<16>(&root, "Type", "UnstructuredGrid")?;
        let (np, ncell) = (f.n_points(), f.n_cells());
        put(&root, "NumberOfPoints", &[1], &[np as i64])?;
        put(&root, "NumberOfCells", &[1], &[ncell as i64])?;
        put(&root, "NumberOfConnectivityIds", &[1], &[f.connectivity.len() as i64])?;
        put(&root, "Points", &[np, 3], f.points.as_flattened())?;
        put(&root, "Connectivity", &[f.connectivity.len()], &f.connectivity)?;
        put(&root, "Offsets", &[f.offsets.len()], &f.offsets)?;
        put(&root, "Types", &[ncell], &f.types)?;
        let pd = root.create_group("PointData")?;
        let cd = root.create_group("CellData")?;
        put(&cd, "cell_kind", &[ncell], &f.cell_kind)?;
        let steps = root.create_group("Steps")?;
        attr(&steps, "NSteps", 0i64)?;
        let m = n_frames;
        let zeros = vec![0i64; m];
        for name in ["PartOffsets", "PointOffsets", "CellOffsets", "ConnectivityIdOffsets"] {
            put(&steps, name, &[m], &zeros)?;
        }
        put(&steps, "NumberOfParts", &[m], &vec![1i64; m])?;
        let pdo = steps.create_group("PointDataOffsets")?;
        let off = |b: usize| (0..m).map(|n| (n * b) as i64).collect::<Vec<_>>();
        put(&pdo, "displacement", &[m], &off(np))?;
        let cdo = steps.create_group("CellDataOffsets")?;
        put(&cdo, "cell_kind", &[m], &zeros)?;
        let mut cells = Vec::new();
        for (name, nc) in cell_arrays(contact) {
            put(&cdo, name, &[m], &off(ncell))?;
            let rest: &[usize] = if nc == 1 { &[] } else { &[nc] };
            cells.push(if name == "stick_slip" {
                Series::create::<u8>(&cd, name, ncell, rest, m)?
            } else {
                Series::create::<f32>(&cd, name, ncell, rest, m)?
            });
        }
        Ok(VtkHdf {
            values: steps
                .new_dataset::<f64>()
                .chunk(1024)
                .shape(Extents::from(Extent::resizable(0)))
                .create("Values")?,
            displacement: Series::create::<f32>(&pd, "displacement", np, &[3], m)?,
            cells,
            steps,
        })
    }

    pub fn open(file: &File, contact: bool) -> hdf5::Result<VtkHdf> {
        let root = file.group("VTKHDF")?;
        let np = root.dataset("Points")?.shape()[0];
        let ncell = root.dataset("Types")?.shape()[0];
        let cd = root.group("CellData")?;
        let cells = cell_arrays(contact)
            .into_iter()
            .map(|(name, _)| Series::open(&cd, name, ncell))
            .collect::<hdf5::Result<Vec<_>>>()?;
        let steps = root.group("Steps")?;
        Ok(VtkHdf {
            values: steps.dataset("Values")?,
            displacement: Series::open(&root.group("PointData")?, "displacement", np)?,
            cells,
            steps,
        })
    }

    /// Append buffered frames (NSteps is not changed).
    pub fn write_frames(&self, raw: &Raw, b: &FrameRows) -> hdf5::Result<()> {
        let (f, k) = (b.first, b.count());
        if k > 0 {
            self.values.resize(f + k)?;
            self.values.write_slice(&b.times, f..f + k)?;
        }
        self.displacement.write_steps(raw, f, k, &b.displacement)?;
        for (series, data) in self.cells.iter().zip(&b.cells) {
            series.write_steps(raw, f, k, data)?;
        }
        if let Some(series) = self.cells.get(6) {
            series.write_steps(raw, f, k, &b.stick_slip)?;
        }
        Ok(())
    }

    pub fn set_nsteps(&self, n: usize) -> hdf5::Result<()> {
        attr(&self.steps, "NSteps", n as i64)
    }

    /// Give every frame series room for exactly `frames` frames, keeping the first `kept`; `Values`
    /// holds exactly the kept frames.
    pub fn set_frames(&mut self, raw: &Raw, frames: usize, kept: usize) -> hdf5::Result<()> {
        self.values.resize(kept.min(frames))?;
        std::iter::once(&mut self.displacement).chain(&mut self.cells).try_for_each(|s| s.set_steps(raw, frames, kept))
    }
}

//! Small helpers over the `hdf5` crate: errors that name the file, static datasets, attributes, and
//! [`Series`], a chunked dataset that grows by a fixed block of rows per time step.

use crate::error::Error;
use hdf5::types::{FixedAscii, VarLenUnicode};
use hdf5::{Dataset, Extent, Extents, Group, H5Type, Hyperslab, Location, Selection, SliceOrIndex};
use ndarray::{ArrayView, IxDyn};
use std::path::{Path, PathBuf};

/// Convert an HDF5 error into the crate's I/O error naming the file.
pub fn io(path: &Path, what: &str) -> impl FnOnce(hdf5::Error) -> Error {
    let path: PathBuf = path.to_path_buf();
    let what = what.to_string();
    move |e| Error::Io { path, msg: format!("{what}: {e}") }
}

/// Write a whole static dataset of the given shape.
pub fn put<T: H5Type>(g: &Group, name: &str, shape: &[usize], data: &[T]) -> hdf5::Result<Dataset> {
    let view = ArrayView::from_shape(IxDyn(shape), data).map_err(|e| hdf5::Error::from(e.to_string()))?;
    g.new_dataset_builder().with_data(&view).create(name)
}

/// Scalar attribute.
pub fn attr<T: H5Type>(loc: &Location, name: &str, v: T) -> hdf5::Result<()> {
    let a = match loc.attr(name) {
        Ok(a) => a,
        Err(_) => loc.new_attr::<T>().create(name)?,
    };
    a.write_scalar(&v)
}

/// 1-D array attribute.
pub fn attr_vec<T: H5Type>(loc: &Location, name: &str, v: &[T]) -> hdf5::Result<()> {
    if loc.attr(name).is_ok() {
        loc.delete_attr(name)?;
    }
    loc.new_attr::<T>().shape(v.len()).create(name)?.write_raw(v)
}

/// Variable-length UTF-8 string attribute (replaced if present).
pub fn attr_str(loc: &Location, name: &str, v: &str) -> hdf5::Result<()> {
    let s: VarLenUnicode =
        v.replace('\0', " ").parse().map_err(|e: hdf5::types::StringError| hdf5::Error::from(e.to_string()))?;
    if loc.attr(name).is_ok() {
        loc.delete_attr(name)?;
    }
    loc.new_attr::<VarLenUnicode>().create(name)?.write_scalar(&s)
}

/// Read a string attribute.
pub fn read_str(loc: &Location, name: &str) -> hdf5::Result<String> {
    Ok(loc.attr(name)?.read_scalar::<VarLenUnicode>()?.as_str().to_string())
}

/// Fixed-length ASCII attribute of exactly the string's length (what VTK's reader wants for `Type`).
pub fn attr_fixed_ascii<const N: usize>(loc: &Location, name: &str, v: &str) -> hdf5::Result<()> {
    let s = FixedAscii::<N>::from_ascii(v.as_bytes()).map_err(|e| hdf5::Error::from(e.to_string()))?;
    loc.new_attr::<FixedAscii<N>>().create(name)?.write_scalar(&s)
}

fn rows(start: usize, end: usize, rest: &[usize]) -> Selection {
    let mut dims = vec![SliceOrIndex::SliceTo { start, step: 1, end, block: 1 }];
    dims.extend(rest.iter().map(|&r| SliceOrIndex::SliceTo { start: 0, step: 1, end: r, block: 1 }));
    Selection::from(Hyperslab::from(dims))
}

/// A chunked dataset of shape (steps · block, rest…) growing by `block` rows per step.
pub struct Series {
    pub ds: Dataset,
    block: usize,
    rest: Vec<usize>,
}

impl Series {
    /// Create with zero rows; one chunk holds `chunk_steps` steps.
    pub fn create<T: H5Type>(
        g: &Group,
        name: &str,
        block: usize,
        rest: &[usize],
        chunk_steps: usize,
    ) -> hdf5::Result<Series> {
        let mut ext = vec![Extent::resizable(0)];
        ext.extend(rest.iter().map(|&r| Extent::fixed(r)));
        let mut chunk = vec![(block * chunk_steps).max(1)];
        chunk.extend(rest.iter().map(|&r| r.max(1)));
        let ds = g.new_dataset::<T>().chunk(chunk).shape(Extents::from(ext)).create(name)?;
        Ok(Series { ds, block, rest: rest.to_vec() })
    }

    /// Open an existing series.
    pub fn open(g: &Group, name: &str, block: usize) -> hdf5::Result<Series> {
        let ds = g.dataset(name)?;
        let rest = ds.shape()[1..].to_vec();
        Ok(Series { ds, block, rest })
    }

    /// Number of complete steps stored.
    pub fn steps(&self) -> usize {
        self.ds.shape()[0] / self.block.max(1)
    }

    /// Write steps first..first+count (resizing as needed); `data` holds count · block · Π rest values.
    pub fn write_steps<T: H5Type>(&self, first: usize, count: usize, data: &[T]) -> hdf5::Result<()> {
        if count == 0 {
            return Ok(());
        }
        let mut shape = vec![count * self.block];
        shape.extend(&self.rest);
        let view = ArrayView::from_shape(IxDyn(&shape), data).map_err(|e| hdf5::Error::from(e.to_string()))?;
        let mut full = vec![(first + count) * self.block];
        full.extend(&self.rest);
        if self.ds.shape()[0] < full[0] {
            self.ds.resize(full)?;
        }
        self.ds.write_slice(&view, rows(first * self.block, (first + count) * self.block, &self.rest))
    }

    /// Keep only the first `steps` steps.
    pub fn truncate(&self, steps: usize) -> hdf5::Result<()> {
        let mut full = vec![steps * self.block];
        full.extend(&self.rest);
        self.ds.resize(full)
    }

    /// Read step n.
    pub fn read<T: H5Type>(&self, n: usize) -> hdf5::Result<Vec<T>> {
        let a = self.ds.read_slice::<T, _, IxDyn>(rows(n * self.block, (n + 1) * self.block, &self.rest))?;
        Ok(a.into_raw_vec_and_offset().0)
    }
}

//! Small helpers over the `hdf5` crate: errors that name the file, static datasets, attributes, and
//! [`Series`], a dataset allocated for the whole run that takes a fixed block of rows per time step.

use crate::error::Error;
use hdf5::plist::dataset_create::{AllocTime, FillTime};
use hdf5::plist::file_access::FileAccessBuilder;
use hdf5::types::{FixedAscii, TypeDescriptor, VarLenUnicode};
use hdf5::{Dataset, Group, H5Type, Hyperslab, Location, Selection, SliceOrIndex};
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

/// Selection of rows start..end (all of the other dimensions `rest`).
pub fn rows(start: usize, end: usize, rest: &[usize]) -> Selection {
    let mut dims = vec![SliceOrIndex::SliceTo { start, step: 1, end, block: 1 }];
    dims.extend(rest.iter().map(|&r| SliceOrIndex::SliceTo { start: 0, step: 1, end: r, block: 1 }));
    Selection::from(Hyperslab::from(dims))
}

/// A time series: a dataset of shape (capacity · block, rest…) holding one block of rows per step,
/// **allocated for the whole run at creation** (contiguous storage, early allocation, no fill).
///
/// Why: the extent never changes and there is no chunk index, so writing a step changes no HDF5
/// metadata at all. The bytes of a step are written with one `pwrite` at the dataset's file offset
/// (`H5Dget_offset`, the public API for direct access to contiguous data) through a second handle on
/// the file ([`Raw`]); they are the dataset's own native little-endian values, so readers see exactly
/// what `H5Dwrite` would have stored. The write has reached the kernel when it returns, so the counters
/// written after it (`completed`, `NSteps`) follow it into the file whatever happens to the process.
/// Measured on Example 5.1 (640 steps): a chunked, resizable series cost ~20 metadata writes and two
/// flushes per step, and `H5Dwrite` through the bindings ~25 µs per series.
///
/// Where there is no offset (an empty dataset) the step goes through `H5Dwrite`, which also goes
/// straight to the file because results files are opened without a sieve buffer ([`file_access`]).
/// Rows beyond the file's `completed` counter hold no data; [`Series::set_steps`] rewrites a series at
/// an exact length (a stopped run) or back at full capacity (resuming one).
pub struct Series {
    pub ds: Dataset,
    block: usize,
    rest: Vec<usize>,
    capacity: usize,
    /// Byte offset of the data in the file and bytes per step, when direct writes apply.
    direct: Option<(u64, usize)>,
    /// The stored (native) type: direct writes must be of exactly this type.
    dtype: TypeDescriptor,
}

/// A second, plain handle on the results file for the direct writes of [`Series`].
pub struct Raw(pub std::fs::File);

impl Raw {
    pub fn open(path: &Path) -> std::io::Result<Raw> {
        // the file this run created or resumes: a regular file with one link, not through a symbolic link
        Ok(Raw(super::paths::open_own(path)?))
    }

    /// All of `bytes` at byte `offset` (one `pwrite` on Unix).
    fn write_at(&self, bytes: &[u8], offset: u64) -> std::io::Result<()> {
        #[cfg(unix)]
        {
            std::os::unix::fs::FileExt::write_all_at(&self.0, bytes, offset)
        }
        #[cfg(not(unix))]
        {
            use std::io::{Seek, SeekFrom, Write};
            let mut f = &self.0;
            f.seek(SeekFrom::Start(offset))?;
            f.write_all(bytes)
        }
    }
}

/// File access properties of a results file: no sieve buffer, so `H5Dwrite` of contiguous datasets
/// goes straight to the file (see [`Series`]); and a small, fixed metadata cache (64 KiB instead of
/// 2 MiB growing to 32 MiB). HDF5 1.10's `H5Fflush` walks every entry of the cache, so with one frame
/// per step (~5,000 virtual datasets for Example 5.1) the per-step flush of the counters cost more
/// than the step: a small cache halved the whole run (measured, `--frame-every 1`). Nothing in a
/// results file is read back during a run, so the cache gains nothing from being larger. For the same
/// reason an object leaves the cache when its last handle closes (`evict_on_close`): the virtual
/// datasets of the XDMF view, created and closed at once, no longer fill the cache until the file is
/// closed, where freeing their layouts was serial work at the end of a run.
///
/// The earliest file format that holds the data (superblock 0, symbol-table groups), as HDF5 1.10
/// wrote by default: HDF5 2 (linked statically, see Cargo.toml) defaults to the 1.8 format, whose
/// compact groups list their members in a different order after `--resume` re-creates a series.
pub fn file_access(p: &mut FileAccessBuilder) -> &mut FileAccessBuilder {
    use hdf5::plist::file_access::{
        CacheDecreaseMode, CacheIncreaseMode, FlashIncreaseMode, LibraryVersion, MetadataCacheConfig,
    };
    const MDC_BYTES: usize = 64 << 10;
    let mdc = MetadataCacheConfig {
        initial_size: MDC_BYTES,
        min_size: MDC_BYTES,
        max_size: MDC_BYTES,
        incr_mode: CacheIncreaseMode::Off,
        flash_incr_mode: FlashIncreaseMode::Off,
        decr_mode: CacheDecreaseMode::Off,
        ..Default::default()
    };
    p.mdc_config(&mdc)
        .sieve_buf_size(0)
        .evict_on_close(true)
        .libver_bounds(LibraryVersion::Earliest, LibraryVersion::latest())
}

fn create_contiguous<T: H5Type>(g: &Group, name: &str, shape: &[usize]) -> hdf5::Result<Dataset> {
    g.new_dataset::<T>()
        .no_chunk()
        .alloc_time(Some(AllocTime::Early))
        .fill_time(FillTime::Never)
        .shape(shape.to_vec())
        .create(name)
}

impl Series {
    /// Create with room for `capacity` steps.
    pub fn create<T: H5Type>(
        g: &Group,
        name: &str,
        block: usize,
        rest: &[usize],
        capacity: usize,
    ) -> hdf5::Result<Series> {
        let mut shape = vec![block * capacity];
        shape.extend(rest);
        let ds = create_contiguous::<T>(g, name, &shape)?;
        Series::wrap(ds, block)
    }

    fn wrap(ds: Dataset, block: usize) -> hdf5::Result<Series> {
        let shape = ds.shape();
        let Some((&rows, rest)) = shape.split_first() else {
            return Err(hdf5::Error::from(format!("{}: a scalar, not a series with a time axis (damaged)", ds.name())));
        };
        let rest = rest.to_vec();
        let capacity = rows / block.max(1);
        let dtype = ds.dtype()?.to_descriptor()?;
        let row_bytes = block * rest.iter().product::<usize>() * dtype.size();
        let contiguous = matches!(ds.layout(), hdf5::plist::dataset_create::Layout::Contiguous);
        let direct =
            if cfg!(target_endian = "little") && contiguous { ds.offset().map(|o| (o, row_bytes)) } else { None };
        Ok(Series { ds, block, rest, capacity, direct, dtype })
    }

    /// The shape of a step's rows after the time axis (empty for a scalar series).
    pub fn rest(&self) -> &[usize] {
        &self.rest
    }

    /// The steps it has room for.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Open an existing series.
    pub fn open(g: &Group, name: &str, block: usize) -> hdf5::Result<Series> {
        Series::wrap(g.dataset(name)?, block)
    }

    /// Write steps first..first+count; `data` holds count · block · Π rest values of the dataset's
    /// type. Steps beyond the capacity are an error (the capacity is the run's number of steps).
    pub fn write_steps<T: H5Type + bytemuck::Pod>(
        &self,
        raw: &Raw,
        first: usize,
        count: usize,
        data: &[T],
    ) -> hdf5::Result<()> {
        if count == 0 {
            return Ok(());
        }
        let name = || self.ds.name();
        if first + count > self.capacity {
            return Err(hdf5::Error::from(format!(
                "{}: steps {first}..{} beyond the {} allocated",
                name(),
                first + count - 1,
                self.capacity
            )));
        }
        let bytes: &[u8] = bytemuck::cast_slice(data);
        match self.direct {
            Some((offset, row)) if bytes.len() == count * row && T::type_descriptor() == self.dtype => raw
                .write_at(bytes, offset + (first * row) as u64)
                .map_err(|e| hdf5::Error::from(format!("{}: {e}", name()))),
            _ => {
                let mut shape = vec![count * self.block];
                shape.extend(&self.rest);
                let view = ArrayView::from_shape(IxDyn(&shape), data).map_err(|e| hdf5::Error::from(e.to_string()))?;
                self.ds.write_slice(&view, rows(first * self.block, (first + count) * self.block, &self.rest))
            }
        }
    }

    /// Rewrite the dataset with room for exactly `steps` steps, keeping the first min(steps, kept) of
    /// its `kept` valid steps (contiguous storage cannot be resized in place).
    pub fn set_steps(&mut self, raw: &Raw, steps: usize, kept: usize) -> hdf5::Result<()> {
        use hdf5::types::{FloatSize, IntSize, TypeDescriptor as D};
        if steps == self.capacity {
            return Ok(());
        }
        match self.dtype.clone() {
            D::Float(FloatSize::U8) => self.rewrite::<f64>(raw, steps, kept),
            D::Float(FloatSize::U4) => self.rewrite::<f32>(raw, steps, kept),
            D::Integer(IntSize::U8) => self.rewrite::<i64>(raw, steps, kept),
            D::Unsigned(IntSize::U8) => self.rewrite::<u64>(raw, steps, kept),
            D::Unsigned(IntSize::U1) => self.rewrite::<u8>(raw, steps, kept),
            other => Err(hdf5::Error::from(format!("{}: unexpected series type {other:?}", self.ds.name()))),
        }
    }

    fn rewrite<T: H5Type + bytemuck::Pod>(&mut self, raw: &Raw, steps: usize, kept: usize) -> hdf5::Result<()> {
        let keep = steps.min(kept);
        if keep > self.capacity {
            let msg = format!("{}: room for {} steps, {keep} were committed (damaged)", self.ds.name(), self.capacity);
            return Err(hdf5::Error::from(msg));
        }
        let data: Vec<T> = if keep == 0 {
            vec![]
        } else {
            self.ds.read_slice::<T, _, IxDyn>(rows(0, keep * self.block, &self.rest))?.into_raw_vec_and_offset().0
        };
        let path = self.ds.name();
        let file = self.ds.file()?;
        file.unlink(&path)?;
        let mut shape = vec![steps * self.block];
        shape.extend(&self.rest);
        let ds = create_contiguous::<T>(&file, &path, &shape)?;
        *self = Series::wrap(ds, self.block)?;
        self.write_steps(raw, 0, keep, &data)
    }

    /// Steps first..first+count.
    pub fn read_steps<T: H5Type>(&self, first: usize, count: usize) -> hdf5::Result<Vec<T>> {
        let sel = rows(first * self.block, (first + count) * self.block, &self.rest);
        Ok(self.ds.read_slice::<T, _, IxDyn>(sel)?.into_raw_vec_and_offset().0)
    }

    /// Bytes of one step (all its rows).
    pub fn step_bytes(&self) -> usize {
        self.block * self.rest.iter().product::<usize>() * self.dtype.size()
    }

    /// Steps first..first+count as the little-endian bytes of the stored type.
    pub fn read_bytes(&self, first: usize, count: usize) -> hdf5::Result<Vec<u8>> {
        use hdf5::types::{FloatSize, IntSize, TypeDescriptor as D};
        fn b<T: H5Type + bytemuck::Pod>(s: &Series, first: usize, count: usize) -> hdf5::Result<Vec<u8>> {
            Ok(bytemuck::cast_slice(&s.read_steps::<T>(first, count)?).to_vec())
        }
        match self.dtype {
            D::Float(FloatSize::U8) => b::<f64>(self, first, count),
            D::Float(FloatSize::U4) => b::<f32>(self, first, count),
            D::Integer(IntSize::U8) => b::<i64>(self, first, count),
            D::Unsigned(IntSize::U8) => b::<u64>(self, first, count),
            D::Unsigned(IntSize::U1) => b::<u8>(self, first, count),
            ref other => Err(hdf5::Error::from(format!("{}: unexpected series type {other:?}", self.ds.name()))),
        }
    }

    /// Read step n.
    pub fn read<T: H5Type>(&self, n: usize) -> hdf5::Result<Vec<T>> {
        let a = self.ds.read_slice::<T, _, IxDyn>(rows(n * self.block, (n + 1) * self.block, &self.rest))?;
        Ok(a.into_raw_vec_and_offset().0)
    }
}

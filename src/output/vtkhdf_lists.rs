//! The lists of the ParaView view (`/VTKHDF`, [`super::vtkhdf`]) that `--resume` keeps as they are: each
//! block's geometry (`NumberOfPoints`, `NumberOfCells`, `NumberOfConnectivityIds`, `Points`,
//! `Connectivity`, `Offsets`, `Types`), its offsets for every frame of the run (`Steps/*Offsets`,
//! `Steps/NumberOfParts`) and the times of the frames it keeps (`Steps/Values`). A list that is not the
//! run's, in length or in an entry, would have ParaView draw the frames on the wrong points or rows: it is
//! damage, named before the file is changed (as `Tresca::misfit` names a series of the wrong shape;
//! `VtkHdf::misfit` asks it of each block).

use hdf5::{Group, H5Type};
use std::fmt::Debug;

/// `n·b` for the frames n of 0..m: where frame n's rows start in a per-frame array of b rows a frame.
pub(super) fn frame_offsets(m: usize, b: usize) -> Vec<i64> {
    (0..m).map(|n| (n * b) as i64).collect()
}

/// 0, k, 2k, … (`cells` + 1 entries): where each cell of k points starts in `Connectivity`.
pub(super) fn cell_offsets(cells: usize, k: usize) -> Vec<i64> {
    (0..=cells).map(|c| (k * c) as i64).collect()
}

/// 0 … np − 1: every cell has points of its own (the broken mesh of [`super::fields`]).
pub(super) fn connectivity(np: usize) -> Vec<i64> {
    (0..np as i64).collect()
}

/// The first list of block `g` (of `points`, `per_cell` points to a cell of VTK type `vtk_type`, the cell
/// arrays `arrays`) that is not the one of a run of `m` frames in all and the frame times `kept`
/// committed; `None` if all are.
pub(super) fn block_misfit(
    g: &Group,
    (per_cell, vtk_type, arrays): (usize, u8, &[(&str, usize)]),
    points: &[[f64; 3]],
    m: usize,
    kept: &[f64],
) -> Option<String> {
    let np = points.len();
    let nc = np / per_cell;
    let mut ints = vec![
        ("NumberOfPoints".to_string(), vec![np as i64]),
        ("NumberOfCells".into(), vec![nc as i64]),
        ("NumberOfConnectivityIds".into(), vec![np as i64]),
        ("Connectivity".into(), connectivity(np)),
        ("Offsets".into(), cell_offsets(nc, per_cell)),
        ("Steps/NumberOfParts".into(), vec![1; m]),
        ("Steps/PointDataOffsets/displacement".into(), frame_offsets(m, np)),
    ];
    for list in ["PartOffsets", "PointOffsets", "CellOffsets", "ConnectivityIdOffsets"] {
        ints.push((format!("Steps/{list}"), vec![0; m]));
    }
    for (array, _) in arrays {
        ints.push((format!("Steps/CellDataOffsets/{array}"), frame_offsets(m, nc)));
    }
    ints.iter()
        .find_map(|(name, want)| differs(g, name, want, false))
        .or_else(|| differs(g, "Types", &vec![vtk_type; nc], false))
        .or_else(|| differs(g, "Points", points.as_flattened(), false))
        // longer once a stopped run's frames are given back their room; `--resume` cuts it to `kept`
        .or_else(|| differs(g, "Steps/Values", kept, true))
}

/// How list `name` of `g` differs from `want` (or, with `prefix`, its first entries), if it does.
fn differs<T: H5Type + PartialEq + Debug>(g: &Group, name: &str, want: &[T], prefix: bool) -> Option<String> {
    let path = format!("{}/{name}", g.name());
    let have = match g.dataset(name).and_then(|d| d.read_raw::<T>()) {
        Ok(v) => v,
        Err(e) => return Some(format!("{path} cannot be read as this run's list ({e})")),
    };
    if have.len() < want.len() || (!prefix && have.len() > want.len()) {
        return Some(format!("{path} holds {} entries, this run's has {}", have.len(), want.len()));
    }
    let i = have.iter().zip(want).position(|(a, b)| a != b)?;
    Some(format!("{path} holds {:?} at entry {i}, this run's {:?}", have[i], want[i]))
}

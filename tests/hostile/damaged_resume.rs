//! Results files damaged between a run and its `--resume` where the step checksums do not look: a series
//! stored as a scalar, the normal series of a unilateral run (not checksummed) cut or widened, and the
//! ParaView view's lists and frame arrays. Each is refused naming the dataset, before the file is changed.

use super::{s, scene_with, tmp};
use crate::common::{bin, fork_guard, spawn, stderr};
use hdf5::Group;
use std::path::Path;

/// Replace the dataset `name` of `g` by one of `shape` (zeros of its type f64, or u8 for `status`).
fn replace(g: &Group, name: &str, shape: &[usize]) {
    g.unlink(name).unwrap();
    if name == "status" {
        g.new_dataset::<u8>().shape(shape.to_vec()).create(name).unwrap();
    } else {
        g.new_dataset::<f64>().shape(shape.to_vec()).create(name).unwrap();
    }
}

/// The system shall refuse a `--resume` whose file has a series of the wrong shape (a scalar `u`, a
/// narrower or wider normal series of a unilateral run), naming the series and calling it damage, with
/// no panic and the file left as it was.
#[test]
fn series_of_the_wrong_shape_are_refused_on_resume() {
    let scene = scene_with("uni.toml", "g_a = \"0.0012\"", "g_a = \"0.0012\"\nlaw = \"unilateral\"");
    let out = tmp("damaged_series.h5");
    for (group, name, shape, want) in [
        ("tresca", "u", vec![], "tresca/u: a scalar"),
        ("tresca/contact", "force", vec![41, 1], "/tresca/contact/force holds rows of shape [1]"),
        ("tresca/contact", "force", vec![41], "/tresca/contact/force holds rows of shape []"),
        ("tresca/contact", "normal_dof", vec![41, 1], "/tresca/contact/normal_dof holds rows of shape [1]"),
        ("tresca/contact", "pressure", vec![41, 5], "/tresca/contact/pressure holds rows of shape [5]"),
        ("tresca/contact", "status", vec![41, 1], "/tresca/contact/status holds rows of shape [1]"),
        ("VTKHDF/body", "Types", vec![], "VTKHDF/body/Types holds a scalar, this run's mesh has 8"),
        ("VTKHDF/contact", "Points", vec![2, 3], "VTKHDF/contact/Points holds 2 rows, this run's mesh has 4"),
        ("VTKHDF/body/PointData", "displacement", vec![24, 3], "the VTKHDF frame arrays hold 1 frames"),
        ("tresca/contact", "gap", vec![7, 2], "/tresca/contact/gap holds 7 steps, 20 were committed"),
        ("VTKHDF/body/CellData", "strain", vec![328, 5], "/VTKHDF/body/CellData/strain: rows of shape [5], not [6]"),
    ] {
        let damage = |f: &hdf5::File| replace(&f.group(group).unwrap(), name, &shape);
        refused_after(&scene, &out, 20, damage, want, &format!("{name} {shape:?}"));
    }
}

/// Run `scene` to `out`, set its counter of committed steps to `completed`, `damage` it, and require that
/// `--resume` exits 1 with `want` in a message calling it damage, no panic and the file left as it was.
fn refused_after(scene: &str, out: &Path, completed: i64, damage: impl FnOnce(&hdf5::File), want: &str, case: &str) {
    let _ = std::fs::remove_file(out);
    let o = spawn(bin().args(["run", scene, "-q", "-o", s(out), "--force"])).wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    {
        let _g = fork_guard();
        let f = hdf5::File::open_rw(out).unwrap();
        f.group("tresca/steps").unwrap().attr("completed").unwrap().write_scalar(&completed).unwrap();
        damage(&f);
    }
    let before = std::fs::read(out).unwrap();
    let o = spawn(bin().args(["run", scene, "-q", "-o", s(out), "--resume"])).wait_with_output().unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{case}: {e}");
    assert!(e.contains(want) && e.contains("damaged") && !e.contains("panicked"), "{case}: {e}");
    assert!(std::fs::read(out).unwrap() == before, "{case}: the file was changed");
}

/// Add 1 (0.5 if f64) to entry `k` of the list `name` (i64, or f64 / u8 by its type) of `f`; with
/// `k` = [`CUT`], cut it to half its length; with `k` = [`FIXED`], store it again with a fixed length.
const CUT: usize = usize::MAX;
const FIXED: usize = usize::MAX - 1;

fn damage_list(f: &hdf5::File, name: &str, k: usize) {
    let ds = f.dataset(name).unwrap();
    let (dir, base) = name.rsplit_once('/').unwrap();
    let dtype = ds.dtype().unwrap();
    macro_rules! bump {
        ($t:ty, $one:expr) => {{
            let mut v: Vec<$t> = ds.read_raw().unwrap();
            if k == CUT && ds.is_resizable() {
                ds.resize(v.len() / 2).unwrap();
            } else if k == CUT || k == FIXED {
                v.truncate(if k == CUT { v.len() / 2 } else { v.len() });
                drop(ds);
                f.group(dir).unwrap().unlink(base).unwrap();
                f.group(dir).unwrap().new_dataset::<$t>().shape([v.len()]).create(base).unwrap().write_raw(&v).unwrap();
            } else {
                v[k] += $one;
                ds.write_raw(&v).unwrap();
            }
        }};
    }
    if dtype.is::<f64>() {
        bump!(f64, 0.5)
    } else if dtype.is::<u8>() {
        bump!(u8, 1)
    } else {
        bump!(i64, 1)
    }
}

/// The system shall refuse a `--resume` whose ParaView view holds a list that `--resume` keeps as it is
/// (the blocks' geometry, their per-frame offsets, the kept frames' times) but that is not this run's,
/// in length or in an entry, naming the list and calling it damage, with the file left as it was.
#[test]
fn view_lists_that_resume_keeps_are_checked() {
    let scene = scene_with("lists.toml", "steps = 40", "steps = 8");
    let out = tmp("damaged_lists.h5");
    for (name, k, want) in [
        ("VTKHDF/body/NumberOfCells", 0, "/VTKHDF/body/NumberOfCells holds 9 at entry 0, this run's 8"),
        ("VTKHDF/body/NumberOfPoints", 0, "/VTKHDF/body/NumberOfPoints holds 25 at entry 0, this run's 24"),
        ("VTKHDF/contact/NumberOfConnectivityIds", 0, "/VTKHDF/contact/NumberOfConnectivityIds holds 5"),
        ("VTKHDF/body/Connectivity", 5, "/VTKHDF/body/Connectivity holds 6 at entry 5, this run's 5"),
        ("VTKHDF/contact/Offsets", CUT, "/VTKHDF/contact/Offsets holds 1 entries, this run's has 3"),
        ("VTKHDF/body/Types", 7, "/VTKHDF/body/Types holds 6 at entry 7, this run's 5"),
        ("VTKHDF/contact/Points", 4, "/VTKHDF/contact/Points holds"),
        ("VTKHDF/body/Steps/NumberOfParts", 3, "/VTKHDF/body/Steps/NumberOfParts holds 2 at entry 3, this run's 1"),
        ("VTKHDF/contact/Steps/PartOffsets", 0, "/VTKHDF/contact/Steps/PartOffsets holds 1 at entry 0, this run's 0"),
        ("VTKHDF/body/Steps/CellOffsets", CUT, "/VTKHDF/body/Steps/CellOffsets holds 4 entries, this run's has 9"),
        ("VTKHDF/body/Steps/PointDataOffsets/displacement", 2, "PointDataOffsets/displacement holds 49 at entry 2"),
        ("VTKHDF/contact/Steps/CellDataOffsets/slip", 1, "/VTKHDF/contact/Steps/CellDataOffsets/slip holds 3 at"),
        ("VTKHDF/body/Steps/Values", 1, "/VTKHDF/body/Steps/Values holds 0.625 at entry 1, this run's 0.125"),
        ("VTKHDF/contact/Steps/Values", CUT, "/VTKHDF/contact/Steps/Values holds 4 entries, this run's has 5"),
        ("VTKHDF/body/Steps/Values", FIXED, "/VTKHDF/body/Steps/Values: a list of fixed length"),
    ] {
        refused_after(&scene, &out, 5, |f| damage_list(f, name, k), want, &format!("{name} {k}"));
    }
}

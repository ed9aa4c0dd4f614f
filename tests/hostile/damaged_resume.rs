//! Results files damaged between a run and its `--resume` where the step checksums do not look: a series
//! stored as a scalar, the normal series of a unilateral run (not checksummed) cut or widened, and the
//! ParaView view's lists and frame arrays. Each is refused naming the dataset, before the file is changed.

use super::{s, scene_with, tmp};
use crate::common::{bin, fork_guard, spawn, stderr};
use hdf5::Group;

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
        let _ = std::fs::remove_file(&out);
        let o = spawn(bin().args(["run", &scene, "-q", "-o", s(&out), "--force"])).wait_with_output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        {
            let _g = fork_guard();
            let f = hdf5::File::open_rw(&out).unwrap();
            f.group("tresca/steps").unwrap().attr("completed").unwrap().write_scalar(&20i64).unwrap();
            replace(&f.group(group).unwrap(), name, &shape);
        }
        let before = std::fs::read(&out).unwrap();
        let o = spawn(bin().args(["run", &scene, "-q", "-o", s(&out), "--resume"])).wait_with_output().unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name} {shape:?}: {e}");
        assert!(e.contains(want) && !e.contains("panicked"), "{name} {shape:?}: {e}");
        assert!(e.contains("damaged"), "{name} {shape:?}: {e}");
        assert!(std::fs::read(&out).unwrap() == before, "{name} {shape:?}: the file was changed");
    }
}

//! `study --differences DIR`: per level l ≥ 2, the elementwise energy density σ(d):ε(d) of
//! d = u_l − P u_{l−1} (the displacements, boundary data's lifting included; constant per triangle of level l; ∇P u_{l−1} = ∇u_{l−1} there on nested meshes) as
//! a cell field, in one XDMF3 file per level with the data inline (XML), which ParaView and meshio
//! open: `DIR/difference_<refine>_<steps>.xdmf`, fields `density_T` (at the final time) and `density_max`
//! (max over the common time nodes) and `energy_T` (density × area, the element's share of
//! |||d(T)|||² without the jump term). Where these are large, refinement still changes the solution.

use super::measure::{Kept, Pair};
use crate::error::{Error, Result};
use crate::fem::prolong::parent_triangles;
use std::fmt::Write as _;
use std::path::Path;

/// Write the file of level `fine` against `coarse` into `dir`; returns its path.
pub fn write(dir: &Path, fine: &Kept, coarse: &Kept) -> Result<std::path::PathBuf> {
    let (fp, cp) = (&fine.problem, &coarse.problem);
    let nt = fp.mesh.tris.len();
    let pair = if fp.scene.mesh_level() == cp.scene.mesh_level() {
        Pair::new(fp, fp, (0..nt).collect())
    } else {
        Pair::new(fp, cp, parent_triangles(&cp.mesh, &fp.mesh)?)
    };
    let mut dmax = vec![0.0f64; nt];
    let mut dlast = vec![0.0; nt];
    for i in 0..fine.u.len() {
        dlast = pair.density(&fine.displacement(i)?, &coarse.displacement(i)?);
        for (m, d) in dmax.iter_mut().zip(&dlast) {
            *m = m.max(*d);
        }
    }
    let energy: Vec<f64> = dlast.iter().enumerate().map(|(t, d)| d * fp.mesh.area(t)).collect();
    let mut x = String::new();
    let w = |x: &mut String, v: &[f64]| {
        for c in v.chunks(8) {
            let line: Vec<String> = c.iter().map(|a| format!("{a:.10e}")).collect();
            let _ = writeln!(x, "{}", line.join(" "));
        }
    };
    let np = fp.mesh.points.len();
    let _ = write!(
        x,
        "<?xml version=\"1.0\"?>\n<Xdmf Version=\"3.0\">\n<Domain>\n<Grid Name=\"difference_{}_{}\" GridType=\"Uniform\">\n\
         <Topology TopologyType=\"Triangle\" NumberOfElements=\"{nt}\">\n<DataItem Dimensions=\"{nt} 3\" NumberType=\"Int\" Format=\"XML\">\n",
        fp.scene.mesh_level(),
        fp.scene.times.len() - 1
    );
    for t in &fp.mesh.tris {
        let _ = writeln!(x, "{} {} {}", t[0], t[1], t[2]);
    }
    let _ = write!(
        x,
        "</DataItem>\n</Topology>\n<Geometry GeometryType=\"XY\">\n<DataItem Dimensions=\"{np} 2\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">\n"
    );
    let pts: Vec<f64> = fp.mesh.points.iter().flatten().copied().collect();
    w(&mut x, &pts);
    x += "</DataItem>\n</Geometry>\n";
    for (name, v) in [("density_T", &dlast), ("density_max", &dmax), ("energy_T", &energy)] {
        let _ = write!(
            x,
            "<Attribute Name=\"{name}\" AttributeType=\"Scalar\" Center=\"Cell\">\n<DataItem Dimensions=\"{nt}\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">\n"
        );
        w(&mut x, v);
        x += "</DataItem>\n</Attribute>\n";
    }
    x += "</Grid>\n</Domain>\n</Xdmf>\n";
    std::fs::create_dir_all(dir).map_err(|e| Error::Io { path: dir.to_path_buf(), msg: e.to_string() })?;
    let path = file_of(dir, fp.scene.mesh_level(), fp.scene.times.len() - 1);
    // under the rule of every output; whether an existing file may be replaced (--force) was decided
    // with the command's other outputs before its first level
    crate::output::guard::write_new(&path, "--differences file", x.as_bytes(), true)?;
    Ok(path)
}

/// The file of the level (`refine`, `steps`) in `dir`.
pub fn file_of(dir: &Path, refine: u32, steps: usize) -> std::path::PathBuf {
    dir.join(format!("difference_{refine}_{steps}.xdmf"))
}

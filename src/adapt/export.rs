//! An adapted mesh written as Gmsh 4.1 ASCII (`adapt --out DIR --gmsh`: `DIR/level_<k>.msh`), so tools
//! that read Gmsh files (`mesh::parse_gmsh`, meshio, the Python re-implementations' scenes with
//! `[mesh] file = …`) take the same mesh: one surface entity of physical group `body` holding the
//! triangles, and per boundary part one curve entity of a physical group of the part's name holding
//! its edges. Coordinates are written with the shortest representation that reads back to the same f64.

use crate::error::Result;
use crate::mesh::Mesh;
use std::fmt::Write as _;
use std::path::Path;

/// The Gmsh 4.1 ASCII text of `mesh`.
pub fn gmsh_text(mesh: &Mesh) -> String {
    let nt = mesh.tag_names.len();
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    let _ = writeln!(s, "{}", nt + 1);
    for (k, name) in mesh.tag_names.iter().enumerate() {
        let _ = writeln!(s, "1 {} \"{name}\"", k + 1);
    }
    let _ = writeln!(s, "2 {} \"body\"\n$EndPhysicalNames\n$Entities\n0 {nt} 1 0", nt + 1);
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in &mesh.points {
        for d in 0..2 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let bbox = format!("{:?} {:?} 0 {:?} {:?} 0", lo[0], lo[1], hi[0], hi[1]);
    for k in 0..nt {
        let _ = writeln!(s, "{} {bbox} 1 {} 0", k + 1, k + 1);
    }
    let _ = writeln!(s, "1 {bbox} 1 {} 0\n$EndEntities\n$Nodes", nt + 1);
    let np = mesh.points.len();
    let _ = writeln!(s, "1 {np} 1 {np}\n2 1 0 {np}");
    for v in 1..=np {
        let _ = writeln!(s, "{v}");
    }
    for p in &mesh.points {
        let _ = writeln!(s, "{:?} {:?} 0", p[0], p[1]);
    }
    s.push_str("$EndNodes\n$Elements\n");
    let by_tag: Vec<Vec<usize>> =
        (0..nt).map(|k| (0..mesh.edges.len()).filter(|&e| mesh.edge_tag[e] == Some(k)).collect()).collect();
    let ne = by_tag.iter().map(Vec::len).sum::<usize>() + mesh.tris.len();
    let _ = writeln!(s, "{} {ne} 1 {ne}", nt + 1);
    let mut id = 0;
    for (k, edges) in by_tag.iter().enumerate() {
        let _ = writeln!(s, "1 {} 1 {}", k + 1, edges.len());
        for &e in edges {
            id += 1;
            let [a, b] = mesh.edges[e];
            let _ = writeln!(s, "{id} {} {}", a + 1, b + 1);
        }
    }
    let _ = writeln!(s, "2 1 2 {}", mesh.tris.len());
    for t in &mesh.tris {
        id += 1;
        let _ = writeln!(s, "{id} {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s.push_str("$EndElements\n");
    s
}

/// Write `mesh` to `path` as Gmsh 4.1 ASCII, under the rule of every output (`output::guard`: an existing
/// file replaced only when `force`).
pub fn write_gmsh(mesh: &Mesh, path: &Path, force: bool) -> Result<()> {
    crate::output::guard::write_new(path, "Gmsh mesh of the level", gmsh_text(mesh).as_bytes(), force)
}

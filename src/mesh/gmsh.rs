//! Reader for Gmsh 4.1 ASCII `.msh` files: 3-node triangles form the mesh, 2-node lines carry the
//! boundary parts through the physical groups of their curves (`$PhysicalNames` + `$Entities`).
//! Nodes not used by any triangle are dropped; duplicate node tags or coordinates are errors.

use super::RawMesh;
use crate::error::{Error, Result};
use std::collections::HashMap;
use std::path::Path;

struct Tokens<'a> {
    src: String,
    lines: std::iter::Peekable<std::iter::Enumerate<std::str::Lines<'a>>>,
    line_no: usize,
}

impl<'a> Tokens<'a> {
    fn err(&self, msg: impl std::fmt::Display) -> Error {
        Error::mesh(&self.src, format!("line {}: {msg}", self.line_no))
    }
    fn line(&mut self) -> Result<&'a str> {
        match self.lines.next() {
            Some((k, l)) => {
                self.line_no = k + 1;
                Ok(l.trim())
            }
            None => {
                Err(Error::mesh(&self.src, format!("unexpected end of file after line {} (truncated?)", self.line_no)))
            }
        }
    }
    fn nums<T: std::str::FromStr>(&mut self, min: usize) -> Result<Vec<T>> {
        let l = self.line()?;
        let v: std::result::Result<Vec<T>, _> = l.split_whitespace().map(str::parse).collect();
        match v {
            Ok(v) if v.len() >= min => Ok(v),
            Ok(v) => Err(self.err(format!("expected at least {min} numbers, found {}", v.len()))),
            Err(_) => Err(self.err(format!("cannot parse numbers in `{l}`"))),
        }
    }
    fn expect(&mut self, tag: &str) -> Result<()> {
        let l = self.line()?;
        if l == tag {
            Ok(())
        } else {
            Err(self.err(format!("expected `{tag}`, found `{l}`")))
        }
    }
}

/// Read a Gmsh 4.1 ASCII file.
pub fn read(path: &Path) -> Result<RawMesh> {
    let text = crate::input::read_text(path, "mesh")?;
    parse(&text, &path.display().to_string())
}

/// Parse Gmsh 4.1 ASCII text; `src` names it in messages.
pub fn parse(text: &str, src: &str) -> Result<RawMesh> {
    let mut tk = Tokens { src: src.to_string(), lines: text.lines().enumerate().peekable(), line_no: 0 };
    let mut file = Sections::default();
    while let Some(&(_, l)) = tk.lines.peek() {
        if l.trim().is_empty() {
            tk.line()?;
            continue;
        }
        let section = tk.line()?.to_string();
        match section.as_str() {
            "$MeshFormat" => file.mesh_format(&mut tk)?,
            "$PhysicalNames" => file.physical_names(&mut tk)?,
            "$Entities" => file.entities(&mut tk)?,
            "$Nodes" => file.nodes(&mut tk)?,
            "$Elements" => file.elements(&mut tk)?,
            s if s.starts_with('$') => {
                // skip unknown sections
                let end = format!("$End{}", &s[1..]);
                while tk.line()? != end {}
            }
            other => return Err(tk.err(format!("expected a section header, found `{other}`"))),
        }
    }
    if !file.seen_format {
        return Err(Error::mesh(src, "missing $MeshFormat section (not a Gmsh file?)"));
    }
    if file.tris_tags.is_empty() {
        return Err(Error::mesh(src, "no 3-node triangles"));
    }
    let UsedNodes { index, points, tris } = used_nodes(src, &file.nodes, &file.tris_tags)?;
    check_duplicate_points(src, &points)?;
    let (tagged, tag_names) = boundary_lines(src, &file, &index)?;
    Ok(RawMesh { source: src.to_string(), points, tris, tagged, tag_names })
}

/// What the sections of a file hold, by Gmsh tag.
#[derive(Default)]
struct Sections {
    /// 1D physical tag → name.
    names: HashMap<i64, String>,
    /// Curve entity → its physical tags.
    curve_phys: HashMap<i64, Vec<i64>>,
    nodes: HashMap<i64, [f64; 2]>,
    tris_tags: Vec<[i64; 3]>,
    /// (nodes, curve entity) of the 2-node lines.
    lines_tags: Vec<([i64; 2], i64)>,
    seen_format: bool,
}

impl Sections {
    /// `$MeshFormat`: ASCII 4.1 only.
    fn mesh_format(&mut self, tk: &mut Tokens) -> Result<()> {
        let f = tk.line()?;
        let v: Vec<&str> = f.split_whitespace().collect();
        if v.len() < 3 || !v[0].starts_with("4.1") {
            return Err(tk.err(format!("unsupported format `{f}` (need Gmsh 4.1)")));
        }
        if v[1] != "0" {
            return Err(tk.err("binary .msh files are not supported; save as ASCII 4.1"));
        }
        tk.expect("$EndMeshFormat")?;
        self.seen_format = true;
        Ok(())
    }

    /// `$PhysicalNames`: the names of the 1D physical groups.
    fn physical_names(&mut self, tk: &mut Tokens) -> Result<()> {
        let n = tk.nums::<usize>(1)?[0];
        for _ in 0..n {
            let l = tk.line()?;
            let mut it = l.splitn(3, char::is_whitespace);
            let (dim, tag, name) = (it.next(), it.next(), it.next());
            let (Some(dim), Some(tag), Some(name)) = (dim, tag, name) else {
                return Err(tk.err("malformed physical name"));
            };
            let (dim, tag): (i64, i64) = match (dim.parse(), tag.parse()) {
                (Ok(d), Ok(t)) => (d, t),
                _ => return Err(tk.err("malformed physical name")),
            };
            if dim == 1 {
                self.names.insert(tag, name.trim().trim_matches('"').to_string());
            }
        }
        tk.expect("$EndPhysicalNames")
    }

    /// `$Entities`: the physical tags of each curve.
    fn entities(&mut self, tk: &mut Tokens) -> Result<()> {
        let c = tk.nums::<usize>(4)?;
        for _ in 0..c[0] {
            tk.line()?;
        }
        for _ in 0..c[1] {
            let v = tk.nums::<f64>(8)?;
            let np = v[7];
            if !(np >= 0.0 && np.fract() == 0.0 && v.len() as f64 >= 8.0 + np) {
                return Err(tk.err("curve entity lists fewer physical tags than it declares"));
            }
            self.curve_phys.insert(v[0] as i64, v[8..8 + np as usize].iter().map(|&x| x as i64).collect());
        }
        for _ in 0..c[2] + c[3] {
            tk.line()?;
        }
        tk.expect("$EndEntities")
    }

    /// `$Nodes`: planar, finite, each tag once.
    fn nodes(&mut self, tk: &mut Tokens) -> Result<()> {
        let h = tk.nums::<usize>(4)?;
        for _ in 0..h[0] {
            let b = tk.nums::<i64>(4)?;
            let param = b[2] != 0;
            let count = usize::try_from(b[3]).map_err(|_| tk.err(format!("negative node count {}", b[3])))?;
            let mut tags = Vec::new();
            for _ in 0..count {
                tags.push(tk.nums::<i64>(1)?[0]);
            }
            for tag in tags {
                let x = tk.nums::<f64>(if param { 4 } else { 3 })?;
                if !(x[0].is_finite() && x[1].is_finite()) {
                    return Err(tk.err("non-finite node coordinate"));
                }
                if x[2] != 0.0 {
                    return Err(tk.err(format!("node {tag} has z = {} (only planar meshes in the xy plane)", x[2])));
                }
                if self.nodes.insert(tag, [x[0], x[1]]).is_some() {
                    return Err(tk.err(format!("node tag {tag} defined twice")));
                }
            }
        }
        tk.expect("$EndNodes")
    }

    /// `$Elements`: 3-node triangles and 2-node lines (points are passed over).
    fn elements(&mut self, tk: &mut Tokens) -> Result<()> {
        let h = tk.nums::<usize>(4)?;
        for _ in 0..h[0] {
            let b = tk.nums::<i64>(4)?;
            let (dim, entity, ty) = (b[0], b[1], b[2]);
            let count = usize::try_from(b[3]).map_err(|_| tk.err(format!("negative element count {}", b[3])))?;
            for _ in 0..count {
                let e = tk.nums::<i64>(2)?;
                match (dim, ty) {
                    (0, 15) => {}
                    (1, 1) if e.len() == 3 => self.lines_tags.push(([e[1], e[2]], entity)),
                    (2, 2) if e.len() == 4 => self.tris_tags.push([e[1], e[2], e[3]]),
                    (1, 1) | (2, 2) => return Err(tk.err("wrong number of nodes for the element type")),
                    _ => {
                        return Err(tk.err(format!(
                            "unsupported element type {ty} in dimension {dim} (only 3-node triangles and 2-node lines)"
                        )))
                    }
                }
            }
        }
        tk.expect("$EndElements")
    }
}

/// The nodes used by triangles, numbered in order of first use.
struct UsedNodes {
    /// Gmsh node tag → point index.
    index: HashMap<i64, usize>,
    points: Vec<[f64; 2]>,
    tris: Vec<[usize; 3]>,
}

/// [`UsedNodes`] of the triangles `tris_tags`.
fn used_nodes(src: &str, nodes: &HashMap<i64, [f64; 2]>, tris_tags: &[[i64; 3]]) -> Result<UsedNodes> {
    let mut index: HashMap<i64, usize> = HashMap::new();
    let mut points = Vec::new();
    let mut tris = Vec::with_capacity(tris_tags.len());
    for t in tris_tags {
        let mut tri = [0; 3];
        for (k, tag) in t.iter().enumerate() {
            let p =
                *nodes.get(tag).ok_or_else(|| Error::mesh(src, format!("triangle refers to undefined node {tag}")))?;
            tri[k] = *index.entry(*tag).or_insert_with(|| {
                points.push(p);
                points.len() - 1
            });
        }
        tris.push(tri);
    }
    Ok(UsedNodes { index, points, tris })
}

/// Two nodes at the same coordinates make a non-conforming mesh: refused.
fn check_duplicate_points(src: &str, points: &[[f64; 2]]) -> Result<()> {
    let mut sorted: Vec<([u64; 2], usize)> =
        points.iter().enumerate().map(|(i, p)| ([p[0].to_bits(), p[1].to_bits()], i)).collect();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0].0 == w[1].0) {
        let p = points[w[0].1];
        return Err(Error::mesh(
            src,
            format!("duplicate nodes at ({}, {}): the mesh is not conforming there", p[0], p[1]),
        ));
    }
    Ok(())
}

/// Boundary edges (vertex pairs) with an index into the part names, as in [`RawMesh`].
type Tagged = Vec<([usize; 2], usize)>;

/// The named boundary lines as (vertex pair, part index), and the part names in order of first use.
fn boundary_lines(src: &str, file: &Sections, index: &HashMap<i64, usize>) -> Result<(Tagged, Vec<String>)> {
    let mut tag_names: Vec<String> = Vec::new();
    let mut tagged = Vec::new();
    for &(pair, entity) in &file.lines_tags {
        let phys = file.curve_phys.get(&entity).cloned().unwrap_or_default();
        let named: Vec<&String> = phys.iter().filter_map(|p| file.names.get(p)).collect();
        let name = match named.as_slice() {
            [] => continue, // an untagged line: its edge will be reported if it is on the boundary
            [n] => (*n).clone(),
            _ => return Err(Error::mesh(src, format!("curve {entity} is in several physical groups: {named:?}"))),
        };
        let tag = match tag_names.iter().position(|n| *n == name) {
            Some(k) => k,
            None => {
                tag_names.push(name);
                tag_names.len() - 1
            }
        };
        let (Some(&a), Some(&b)) = (index.get(&pair[0]), index.get(&pair[1])) else {
            return Err(Error::mesh(
                src,
                format!("boundary line of `{}` refers to a node of no triangle", tag_names[tag]),
            ));
        };
        tagged.push(([a, b], tag));
    }
    Ok((tagged, tag_names))
}

#[cfg(test)]
mod tests {
    use super::*;

    pub const SQUARE: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n3\n1 1 \"clamp\"\n1 2 \"free\"\n2 3 \"body\"\n$EndPhysicalNames\n$Entities\n0 2 1 0\n1 0 0 0 1 0 0 1 1 0\n2 0 0 0 1 1 0 1 2 0\n1 0 0 0 1 1 0 1 3 0\n$EndEntities\n$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n$Elements\n3 6 1 6\n1 1 1 1\n1 4 1\n1 2 1 3\n2 1 2\n3 2 3\n4 3 4\n2 1 2 2\n5 1 2 3\n6 1 3 4\n$EndElements\n";

    #[test]
    fn reads_a_two_triangle_square() {
        let raw = parse(SQUARE, "sq.msh").unwrap();
        assert_eq!(raw.points.len(), 4);
        assert_eq!(raw.tris.len(), 2);
        assert_eq!(raw.tagged.len(), 4);
        assert_eq!(raw.tag_names, vec!["clamp".to_string(), "free".to_string()]);
    }

    #[test]
    fn truncated_file_is_an_error_not_a_panic() {
        for cut in [10, 60, 200, SQUARE.len() - 20] {
            let e = parse(&SQUARE[..cut], "sq.msh");
            assert!(e.is_err(), "cut at {cut} parsed");
        }
    }
}

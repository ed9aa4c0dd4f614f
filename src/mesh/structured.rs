//! Structured meshes of a quadrilateral c0 c1 c2 c3 (counter-clockwise): the points are
//! p(i, j) = bilinear image of (i/n, j/m), and each cell is split by one diagonal, all parallel.
//! Sides are tagged `bottom` (c0→c1), `right` (c1→c2), `top` (c2→c3), `left` (c3→c0).

use super::{area2, Diagonal, RawMesh};
use crate::error::{Error, Result};

/// Generate the n × m mesh.
pub fn generate(c: &[[f64; 2]; 4], [n, m]: [usize; 2], diagonal: Diagonal) -> Result<RawMesh> {
    let src = "structured mesh";
    if area2(c[0], c[1], c[2]) <= 0.0
        || area2(c[0], c[2], c[3]) <= 0.0
        || area2(c[0], c[1], c[3]) <= 0.0
        || area2(c[1], c[2], c[3]) <= 0.0
    {
        return Err(Error::mesh(src, "corners must form a convex quadrilateral listed counter-clockwise"));
    }
    if (n + 1).checked_mul(m + 1).is_none_or(|p| p > 200_000_000) {
        return Err(Error::mesh(src, format!("{n} x {m} cells is too many")));
    }
    let id = |i: usize, j: usize| j * (n + 1) + i;
    let mut points = Vec::with_capacity((n + 1) * (m + 1));
    for j in 0..=m {
        for i in 0..=n {
            let (s, r) = (i as f64 / n as f64, j as f64 / m as f64);
            let w = [(1.0 - s) * (1.0 - r), s * (1.0 - r), s * r, (1.0 - s) * r];
            let x = (0..4).map(|k| w[k] * c[k][0]).sum();
            let y = (0..4).map(|k| w[k] * c[k][1]).sum();
            points.push([x, y]);
        }
    }
    let mut tris = Vec::with_capacity(2 * n * m);
    for j in 0..m {
        for i in 0..n {
            let (p00, p10, p11, p01) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            match diagonal {
                Diagonal::First => {
                    tris.push([p00, p10, p11]);
                    tris.push([p00, p11, p01]);
                }
                Diagonal::Second => {
                    tris.push([p00, p10, p01]);
                    tris.push([p10, p11, p01]);
                }
            }
        }
    }
    let mut tagged = Vec::with_capacity(2 * (n + m));
    for i in 0..n {
        tagged.push(([id(i, 0), id(i + 1, 0)], 0));
        tagged.push(([id(i, m), id(i + 1, m)], 2));
    }
    for j in 0..m {
        tagged.push(([id(n, j), id(n, j + 1)], 1));
        tagged.push(([id(0, j), id(0, j + 1)], 3));
    }
    let tag_names = ["bottom", "right", "top", "left"].map(String::from).to_vec();
    Ok(RawMesh { source: src.into(), points, tris, tagged, tag_names })
}

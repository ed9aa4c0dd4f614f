//! The loads on the constrained components (the energy audit's reactions): (lⁿ, ψ_k) of f and g
//! alone on the components that boundary data fix (both axes of a Dirichlet edge with data, the normal of
//! a Γ_C edge with a gap), from the load terms' own quadrature points.

use super::{LoadPoint, Loads, PointWeights};
use crate::error::Result;
use crate::fem::lifting::BoundaryData;
use crate::fem::space::CrSpace;
use crate::scene::expr::{BoundSet, ExprSet, Vec2Expr};

impl Loads {
    /// (lⁿ, ψ_k) of the loads f and g alone (without the lifting's part) on the constrained components
    /// of `fem::lifting::BoundaryData::constrained`, in that order; empty without boundary data.
    pub fn constrained(&self, t: f64) -> Result<Vec<f64>> {
        let Some(lift) = &self.lift else {
            return Ok(Vec::new());
        };
        let mut out = vec![0.0; lift.n_constrained];
        let mut values = Vec::new();
        for (expr, points) in &lift.constrained {
            expr.eval(t, &mut values)?;
            for (v, feeds) in values.chunks_exact(2).zip(points) {
                for &(c, w, a) in feeds {
                    out[c] += w * (a[0] * v[0] + a[1] * v[1]);
                }
            }
        }
        Ok(out)
    }
}

/// The load terms at their points that feed a constrained component of `data` (both axes of a
/// Dirichlet edge with data, the normal of a Γ_C edge with a gap), and the number of such components.
pub(super) fn constrained_terms(
    raw: &[(&Vec2Expr, Vec<LoadPoint>)],
    data: &BoundaryData,
    space: &CrSpace,
) -> (Vec<(BoundSet, Vec<PointWeights>)>, usize) {
    let comps = data.constrained(&space.contact);
    let mut of_edge: Vec<Vec<(usize, [f64; 2])>> = vec![Vec::new(); space.edge_dof.len()];
    for (c, &(e, a)) in comps.iter().enumerate() {
        of_edge[e].push((c, a));
    }
    let mut out = Vec::new();
    for (e, pts) in raw {
        let (mut points, mut feeds) = (Vec::new(), Vec::new());
        for p in pts {
            let f: PointWeights =
                p.edges.iter().flat_map(|&(edge, w)| of_edge[edge].iter().map(move |&(c, a)| (c, w, a))).collect();
            if !f.is_empty() {
                points.push(p.x);
                feeds.push(f);
            }
        }
        if !points.is_empty() {
            out.push((ExprSet::new(&[&e.0[0], &e.0[1]]).bind(points), feeds));
        }
    }
    (out, comps.len())
}

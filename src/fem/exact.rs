//! The exact solution at fixed quadrature points, time node after time node: the six values
//! u₀, u₁, ∂u₀/∂x, ∂u₀/∂y, ∂u₁/∂x, ∂u₁/∂y at the points of every element, for the true error norms
//! ([`super::norms`]). Elements go in batches of [`LANES`]; a batch's values are laid out value, point
//! of the element, element (`out[(k · per_element + q) · LANES + e]`), so that the norms are loops
//! over the elements of a batch, which the compiler vectorises.
//!
//! **Separated.** When every one of the six expressions is a sum of time factors times space parts
//! (`Expr::separate`, as for the loads of [`super::loads`]),
//!   v_k(x, t) = Σ_j τ_j(t) s_kj(x),
//! the space parts are evaluated at the points once, and a time node costs the factors τ_j(tₙ) and one
//! multiply-add per part and point: for mms_stop 12 parts with 4 distinct factors, against the 26
//! instructions per point of the compiled program on its cached spatial values. The two routes compute
//! the same real function with the products reassociated, so values move by a few ulps of the parts
//! (a test bounds this at 1e-14 of their size).
//!
//! **Bound.** Otherwise (fronts moving in time such as `max(x − t, 0)`, more than [`MAX_PARTS`] parts,
//! a space part that is not finite at a point) the expressions are compiled together and bound to the
//! points ([`BoundSet`]): their subterms that do not depend on t are evaluated once.
//!
//! A separated value that is not finite (a factor or a part overflowing, an expression undefined at a
//! point) sends that range of points to the bound route, which gives today's values or today's error
//! naming the expression, the point and the time.

use crate::error::Result;
use crate::scene::expr::factor_slot;
use crate::scene::expr::program::{Program, LANES};
use crate::scene::expr::{BoundSet, Expr, ExprSet};
use crate::scene::Exact;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;

/// Values per point: u₀, u₁ and the four entries of ∇u.
pub const VALUES: usize = 6;

/// Most space parts (over the six values) evaluated per point by the separated route; beyond it the
/// memory a node reads per point outgrows the bound program's.
pub const MAX_PARTS: usize = 48;

/// Batches of elements per chunk of the space parts' evaluation.
const CHUNK_BATCHES: usize = 4;

/// The exact solution bound to its points (see the module doc).
pub struct ExactAt {
    exprs: [Expr; VALUES],
    /// The points, element by element (`per_element` each).
    points: Vec<[f64; 2]>,
    per_element: usize,
    separated: Option<Separated>,
    /// The bound program: built at once when the solution does not separate, else on first need.
    bound: OnceLock<BoundSet>,
}

/// v_k(x_p, t) = Σ_{i ∈ parts of k} τ_{factor[i]}(t) · s_i(x_p), the parts summed in order.
struct Separated {
    /// τ_j(t), one output per distinct time factor.
    factors: Program,
    /// Parts of value k: `first[k]..first[k + 1]`.
    first: [usize; VALUES + 1],
    /// The time factor of each part.
    factor: Vec<usize>,
    /// The space parts at the points by batch of elements: batch, part, point of the element, element.
    space: Vec<f64>,
}

/// The time factors at one time node (`None`: the bound route serves this node).
pub struct Node {
    t: f64,
    tau: Option<Vec<f64>>,
}

impl ExactAt {
    /// Bind `exact` to `points`, `per_element` points of each element in turn: separated if it
    /// separates, else compiled and bound.
    pub fn new(exact: &Exact, points: Vec<[f64; 2]>, per_element: usize) -> ExactAt {
        let [u0, u1] = &exact.u.0;
        let [[g00, g01], [g10, g11]] = &exact.grad;
        let exprs = [u0, u1, g00, g01, g10, g11].map(Expr::clone);
        let separated = Separated::new(&exprs, &points, per_element);
        let ex = ExactAt { exprs, points, per_element, separated, bound: OnceLock::new() };
        if ex.separated.is_none() {
            ex.bound();
        }
        ex
    }

    fn bound(&self) -> &BoundSet {
        self.bound.get_or_init(|| {
            let e = &self.exprs;
            ExprSet::new(&[&e[0], &e[1], &e[2], &e[3], &e[4], &e[5]]).bind(self.points.clone())
        })
    }

    /// The points, given back.
    pub fn into_points(self) -> Vec<[f64; 2]> {
        self.points
    }

    /// True if the separated route serves the nodes.
    pub fn is_separated(&self) -> bool {
        self.separated.is_some()
    }

    /// The time factors at t.
    pub fn node(&self, t: f64) -> Node {
        let tau = self.separated.as_ref().and_then(|s| {
            let mut tau = vec![0.0; s.factors.n_outputs()];
            s.factors.eval_point(0.0, 0.0, t, &mut tau);
            tau.iter().all(|v| v.is_finite()).then_some(tau)
        });
        Node { t, tau }
    }

    /// The values at the points of the `n` ≤ [`LANES`] elements of batch `batch` (elements
    /// batch · LANES, …) at `node` into `out`: [`VALUES`] · per_element · LANES values, laid out as
    /// in the module doc (lanes past n hold zeros or the padding's values). An error names the first
    /// expression, point and time with a value that is not finite.
    pub fn eval_batch(&self, node: &Node, batch: usize, n: usize, out: &mut Vec<f64>) -> Result<()> {
        let pe = self.per_element;
        out.clear();
        out.resize(VALUES * pe * LANES, 0.0);
        if let (Some(s), Some(tau)) = (&self.separated, &node.tau) {
            if s.eval_batch(tau, batch, pe, out) {
                return Ok(());
            }
        }
        let mut values = Vec::with_capacity(n * pe * VALUES);
        self.bound().eval_range(batch * LANES * pe, n * pe, node.t, &mut values)?;
        out.fill(0.0);
        for (p, v) in values.chunks_exact(VALUES).enumerate() {
            for (k, &x) in v.iter().enumerate() {
                out[(k * pe + p % pe) * LANES + p / pe] = x;
            }
        }
        Ok(())
    }
}

impl Separated {
    /// The separated form of `exprs` at `points`, if all six separate within [`MAX_PARTS`] parts and
    /// every space part is finite at every point.
    fn new(exprs: &[Expr; VALUES], points: &[[f64; 2]], pe: usize) -> Option<Separated> {
        let mut taus = Vec::new();
        let (mut first, mut factor, mut names, mut trees) = ([0; VALUES + 1], Vec::new(), Vec::new(), Vec::new());
        for (k, e) in exprs.iter().enumerate() {
            for (tau, space) in e.separate()? {
                factor.push(factor_slot(&mut taus, tau));
                names.push(e);
                trees.push(space);
            }
            first[k + 1] = factor.len();
        }
        if factor.is_empty() || factor.len() > MAX_PARTS {
            return None;
        }
        let set = ExprSet::derived(&names, &trees.iter().collect::<Vec<_>>());
        let np = factor.len();
        // one batch of elements: LANES · pe points, np · pe · LANES values
        let per_batch = np * pe * LANES;
        let mut space = vec![0.0; points.len().div_ceil(pe * LANES) * per_batch];
        // evaluated and laid out chunk by chunk (no point-major copy of all the values)
        let finite = AtomicBool::new(true);
        crate::parallel::for_chunks(&mut space, CHUNK_BATCHES * per_batch, 1, |c, chunk| {
            let first = c * CHUNK_BATCHES * LANES * pe;
            let pts = &points[first..(first + chunk.len() / np).min(points.len())];
            let mut values = Vec::with_capacity(pts.len() * np);
            if set.eval(pts, 0.0, &mut values).is_err() {
                finite.store(false, Ordering::Relaxed);
                return;
            }
            for (p, v) in values.chunks_exact(np).enumerate() {
                let (e, q) = (p / pe, p % pe);
                for (i, &x) in v.iter().enumerate() {
                    chunk[e / LANES * per_batch + (i * pe + q) * LANES + e % LANES] = x;
                }
            }
        });
        if !finite.into_inner() {
            return None;
        }
        Some(Separated {
            factors: Program::new(&taus.iter().map(|(_, tau)| tau).collect::<Vec<_>>()),
            first,
            factor,
            space,
        })
    }

    /// The values of batch `batch` (pe points per element) into `out` (zeroed, laid out as in the
    /// module doc); false if one is not finite.
    fn eval_batch(&self, tau: &[f64], batch: usize, pe: usize, out: &mut [f64]) -> bool {
        let coef: Vec<f64> = self.factor.iter().map(|&j| tau[j]).collect();
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2.
            return unsafe { self.combine_avx2(&coef, batch, pe, out) };
        }
        self.combine(&coef, batch, pe, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn combine_avx2(&self, coef: &[f64], batch: usize, pe: usize, out: &mut [f64]) -> bool {
        self.combine(coef, batch, pe, out)
    }

    /// v_k = Σ_i c_i s_i row by row: loops over the lanes, as in `scene::expr::eval` (the same
    /// operations with or without AVX2: no fused multiply-add).
    #[inline(always)]
    fn combine(&self, coef: &[f64], batch: usize, pe: usize, out: &mut [f64]) -> bool {
        let np = self.factor.len();
        let space = &self.space[batch * np * pe * LANES..][..np * pe * LANES];
        let mut finite = true;
        for k in 0..VALUES {
            for q in 0..pe {
                let row: &mut [f64] = &mut out[(k * pe + q) * LANES..][..LANES];
                for i in self.first[k]..self.first[k + 1] {
                    let (c, s) = (coef[i], &space[(i * pe + q) * LANES..][..LANES]);
                    row.iter_mut().zip(s).for_each(|(r, s)| *r += c * s);
                }
                finite &= row.iter().all(|v| v.is_finite());
            }
        }
        finite
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::expr::Vec2Expr;

    fn exact(u: [&str; 2], g: [[&str; 2]; 2]) -> Exact {
        let s = |a: &str| a.to_string();
        let p = |k: &str, a: &str| Expr::parse(k, a).unwrap();
        Exact {
            u: Vec2Expr::parse("exact.u", &[s(u[0]), s(u[1])]).unwrap(),
            grad: [[p("g00", g[0][0]), p("g01", g[0][1])], [p("g10", g[1][0]), p("g11", g[1][1])]],
        }
    }

    fn points(n: usize) -> Vec<[f64; 2]> {
        (0..n).map(|i| [(i as f64 * 0.37).sin() * 0.5 + 0.5, (i as f64 * 0.11).cos() * 0.5 + 0.5]).collect()
    }

    /// The values of batch b (n elements of pe points) from the bound program, in the batch layout.
    fn reference(set: &BoundSet, b: usize, n: usize, pe: usize, t: f64) -> Vec<f64> {
        let mut v = Vec::new();
        set.eval_range(b * LANES * pe, n * pe, t, &mut v).unwrap();
        let mut out = vec![0.0; VALUES * pe * LANES];
        for (p, x) in v.chunks_exact(VALUES).enumerate() {
            for k in 0..VALUES {
                out[(k * pe + p % pe) * LANES + p / pe] = x[k];
            }
        }
        out
    }

    /// Requirement: the separated route gives the bound program's values to within a few ulps of the
    /// parts (1e-14 of their size: the same terms, products reassociated) at every point and time, in
    /// full batches and in the last, shorter one.
    #[test]
    fn separated_values_agree_with_the_bound_program() {
        let ex = exact(
            ["(t+1)*cos(x)*y^2 + (t - max(t - 1/3, 0))*(3*x/20 + 3/10)", "y*(1-y)*(t/2+1)*(x+1)/20"],
            [
                ["-(t+1)*sin(x)*y^2 + 3/20*(t - max(t-1/3, 0))", "2*y*(t+1)*cos(x)"],
                ["y*(1-y)*(t/2+1)/20", "(1-2*y)*(t/2+1)*(x+1)/20"],
            ],
        );
        let (pe, elements) = (6, 2 * LANES + 5);
        let pts = points(pe * elements);
        let at = ExactAt::new(&ex, pts.clone(), pe);
        assert!(at.is_separated());
        let e = &at.exprs;
        let set = ExprSet::new(&[&e[0], &e[1], &e[2], &e[3], &e[4], &e[5]]).bind(pts.clone());
        let mut a = Vec::new();
        for t in [0.0, 0.2, 1.0 / 3.0, 0.5, 1.0] {
            for (b, n) in [(0, LANES), (2, 5)] {
                at.eval_batch(&at.node(t), b, n, &mut a).unwrap();
                let r = reference(&set, b, n, pe, t);
                let scale = r.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                let worst = (0..VALUES * pe)
                    .flat_map(|row| (0..n).map(move |e| row * LANES + e))
                    .map(|i| (a[i] - r[i]).abs())
                    .fold(0.0, f64::max);
                assert!(worst <= 1e-14 * scale, "t = {t}, batch {b}: {worst:e} of {scale:e}");
            }
        }
    }

    /// Requirement: a solution that does not separate in time uses the bound program (its values
    /// exactly), and a value that is not finite is an error naming the expression.
    #[test]
    fn a_moving_front_is_bound_and_a_pole_is_reported() {
        let front = exact(["max(x - t, 0)", "y*t"], [["0", "0"], ["0", "0"]]);
        let (pe, pts) = (6, points(6 * LANES));
        let at = ExactAt::new(&front, pts.clone(), pe);
        assert!(!at.is_separated());
        let set = ExprSet::new(&[&at.exprs[0], &at.exprs[1], &at.exprs[2], &at.exprs[3], &at.exprs[4], &at.exprs[5]])
            .bind(pts.clone());
        let mut a = Vec::new();
        at.eval_batch(&at.node(0.4), 0, LANES, &mut a).unwrap();
        assert!(a.iter().zip(reference(&set, 0, LANES, pe, 0.4)).all(|(x, y)| x.to_bits() == y.to_bits()));
        let pole = exact(["t/(x - x)", "0"], [["0", "0"], ["0", "0"]]);
        let at = ExactAt::new(&pole, pts, pe);
        let err = at.eval_batch(&at.node(0.5), 0, LANES, &mut a).unwrap_err().to_string();
        assert!(err.contains("x - x"), "{err}");
    }
}

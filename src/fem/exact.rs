//! The exact solution at fixed quadrature points, time node after time node: the six values
//! u₀, u₁, ∂u₀/∂x, ∂u₀/∂y, ∂u₁/∂x, ∂u₁/∂y of every point, point-major, for the true error norms
//! ([`super::norms`]).
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

/// Batches of [`LANES`] points per chunk of the space parts' evaluation.
const CHUNK_BATCHES: usize = 16;

/// The exact solution bound to its points (see the module doc).
pub struct ExactAt {
    exprs: [Expr; VALUES],
    points: Vec<[f64; 2]>,
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
    /// The space parts at the points in batches of [`LANES`] points: batch, part, lane (so a batch's
    /// multiply-adds are loops over lanes, which the compiler vectorises).
    space: Vec<f64>,
}

/// The time factors at one time node (`None`: the bound route serves this node).
pub struct Node {
    t: f64,
    tau: Option<Vec<f64>>,
}

impl ExactAt {
    /// Bind `exact` to `points`: separated if it separates, else compiled and bound.
    pub fn new(exact: &Exact, points: Vec<[f64; 2]>) -> ExactAt {
        let [u0, u1] = &exact.u.0;
        let [[g00, g01], [g10, g11]] = &exact.grad;
        let exprs = [u0, u1, g00, g01, g10, g11].map(Expr::clone);
        let separated = Separated::new(&exprs, &points);
        let ex = ExactAt { exprs, points, separated, bound: OnceLock::new() };
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

    /// The values at the points `start..start + n` at `node` into `out` (n · [`VALUES`], point-major);
    /// `start` must be a multiple of `program::LANES`. An error names the first expression, point and
    /// time with a value that is not finite.
    pub fn eval_range(&self, node: &Node, start: usize, n: usize, out: &mut Vec<f64>) -> Result<()> {
        if let (Some(s), Some(tau)) = (&self.separated, &node.tau) {
            if s.eval_range(tau, start, n, out) {
                return Ok(());
            }
        }
        self.bound().eval_range(start, n, node.t, out)
    }
}

impl Separated {
    /// The separated form of `exprs` at `points`, if all six separate within [`MAX_PARTS`] parts and
    /// every space part is finite at every point.
    fn new(exprs: &[Expr; VALUES], points: &[[f64; 2]]) -> Option<Separated> {
        let mut keys: Vec<String> = Vec::new();
        let mut taus = Vec::new();
        let (mut first, mut factor, mut names, mut trees) = ([0; VALUES + 1], Vec::new(), Vec::new(), Vec::new());
        for (k, e) in exprs.iter().enumerate() {
            for (tau, space) in e.separate()? {
                let key = format!("{tau:?}");
                let j = keys.iter().position(|x| *x == key).unwrap_or_else(|| {
                    keys.push(key);
                    taus.push(tau);
                    keys.len() - 1
                });
                factor.push(j);
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
        let mut space = vec![0.0; points.len().div_ceil(LANES) * np * LANES];
        // evaluated and laid out chunk by chunk (no point-major copy of all the values)
        let finite = AtomicBool::new(true);
        crate::parallel::for_chunks(&mut space, CHUNK_BATCHES * np * LANES, 1, |c, chunk| {
            let first = c * CHUNK_BATCHES * LANES;
            let pts = &points[first..(first + chunk.len() / np).min(points.len())];
            let mut values = Vec::with_capacity(pts.len() * np);
            if set.eval(pts, 0.0, &mut values).is_err() {
                finite.store(false, Ordering::Relaxed);
                return;
            }
            for (p, v) in values.chunks_exact(np).enumerate() {
                for (i, &x) in v.iter().enumerate() {
                    chunk[(p / LANES * np + i) * LANES + p % LANES] = x;
                }
            }
        });
        if !finite.into_inner() {
            return None;
        }
        Some(Separated { factors: Program::new(&taus.iter().collect::<Vec<_>>()), first, factor, space })
    }

    /// The values at points `start..start + n` into `out`; false if one is not finite. `start` is a
    /// multiple of [`LANES`].
    fn eval_range(&self, tau: &[f64], start: usize, n: usize, out: &mut Vec<f64>) -> bool {
        out.clear();
        out.resize(n * VALUES, 0.0);
        let coef: Vec<f64> = self.factor.iter().map(|&j| tau[j]).collect();
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor supports AVX2.
            return unsafe { self.batches_avx2(&coef, start / LANES, out) };
        }
        self.batches(&coef, start / LANES, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn batches_avx2(&self, coef: &[f64], first: usize, out: &mut [f64]) -> bool {
        self.batches(coef, first, out)
    }

    /// The batches from `first` on into `out` (point-major): per value a loop over lanes, as in
    /// `scene::expr::eval` (the same operations with or without AVX2: no fused multiply-add).
    #[inline(always)]
    fn batches(&self, coef: &[f64], first: usize, out: &mut [f64]) -> bool {
        let np = self.factor.len();
        let mut finite = true;
        let mut rows = [[0.0f64; LANES]; VALUES];
        for (b, o) in out.chunks_mut(LANES * VALUES).enumerate() {
            let batch = &self.space[(first + b) * np * LANES..][..np * LANES];
            for (k, row) in rows.iter_mut().enumerate() {
                *row = [0.0; LANES];
                for i in self.first[k]..self.first[k + 1] {
                    let (c, s) = (coef[i], &batch[i * LANES..(i + 1) * LANES]);
                    row.iter_mut().zip(s).for_each(|(r, s)| *r += c * s);
                }
                finite &= row.iter().all(|v| v.is_finite());
            }
            for (l, o) in o.chunks_exact_mut(VALUES).enumerate() {
                for (k, o) in o.iter_mut().enumerate() {
                    *o = rows[k][l];
                }
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

    /// Requirement: the separated route gives the bound program's values to within a few ulps of the
    /// parts (1e-14 of their size: the same terms, products reassociated) at every point and time.
    #[test]
    fn separated_values_agree_with_the_bound_program() {
        let ex = exact(
            ["(t+1)*cos(x)*y^2 + (t - max(t - 1/3, 0))*(3*x/20 + 3/10)", "y*(1-y)*(t/2+1)*(x+1)/20"],
            [
                ["-(t+1)*sin(x)*y^2 + 3/20*(t - max(t-1/3, 0))", "2*y*(t+1)*cos(x)"],
                ["y*(1-y)*(t/2+1)/20", "(1-2*y)*(t/2+1)*(x+1)/20"],
            ],
        );
        let pts = points(3 * 64);
        let at = ExactAt::new(&ex, pts.clone());
        assert!(at.is_separated());
        let e = &at.exprs;
        let reference = ExprSet::new(&[&e[0], &e[1], &e[2], &e[3], &e[4], &e[5]]).bind(pts.clone());
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for t in [0.0, 0.2, 1.0 / 3.0, 0.5, 1.0] {
            at.eval_range(&at.node(t), 64, 128, &mut a).unwrap();
            reference.eval_range(64, 128, t, &mut b).unwrap();
            let scale = b.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            assert!(worst <= 1e-14 * scale, "t = {t}: {worst:e} of {scale:e}");
        }
    }

    /// Requirement: a solution that does not separate in time uses the bound program (its values
    /// exactly), and a value that is not finite is an error naming the expression.
    #[test]
    fn a_moving_front_is_bound_and_a_pole_is_reported() {
        let front = exact(["max(x - t, 0)", "0"], [["0", "0"], ["0", "0"]]);
        let pts = points(64);
        let at = ExactAt::new(&front, pts.clone());
        assert!(!at.is_separated());
        let pole = exact(["t/(x - x)", "0"], [["0", "0"], ["0", "0"]]);
        let at = ExactAt::new(&pole, pts);
        let err = at.eval_range(&at.node(0.5), 0, 64, &mut Vec::new()).unwrap_err().to_string();
        assert!(err.contains("x - x"), "{err}");
    }
}

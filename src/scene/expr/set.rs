//! Sets of expressions compiled into one program ([`ExprSet`]), and bound to fixed points
//! ([`BoundSet`]).

use super::program::Program;
use super::sym::Sym;
use super::{check, Expr};
use crate::error::Result;

/// Several expressions compiled into one program (subexpressions shared between them), evaluated
/// together over many points.
#[derive(Clone, Debug)]
pub struct ExprSet {
    exprs: Vec<Expr>,
    program: Program,
}

impl ExprSet {
    /// Compile `exprs` together; output k is `exprs[k]`.
    pub fn new(exprs: &[&Expr]) -> ExprSet {
        let trees: Vec<&Sym> = exprs.iter().map(|e| &*e.tree).collect();
        ExprSet { exprs: exprs.iter().map(|&e| e.clone()).collect(), program: Program::new(&trees) }
    }

    /// Trees derived from `names` (parts of them, [`Expr::separate`]) compiled together; output k is
    /// `trees[k]`, and a non-finite value is reported as one of `names[k]`.
    pub fn derived(names: &[&Expr], trees: &[&Sym]) -> ExprSet {
        assert_eq!(names.len(), trees.len(), "one name per derived tree");
        ExprSet { exprs: names.iter().map(|&e| e.clone()).collect(), program: Program::new(trees) }
    }

    /// Number of expressions.
    pub fn len(&self) -> usize {
        self.exprs.len()
    }

    /// True if the set is empty.
    pub fn is_empty(&self) -> bool {
        self.exprs.is_empty()
    }

    /// The compiled program.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Varying instructions per point (the compiled work).
    pub fn n_instructions(&self) -> usize {
        self.program.n_instructions()
    }

    /// Every expression at every point at time t, point-major (`out[i * len + k]`). A non-finite value
    /// is an error naming the expression and the point (the first point in order that has one).
    pub fn eval(&self, points: &[[f64; 2]], t: f64, out: &mut Vec<f64>) -> Result<()> {
        let finite = self.program.eval(points, t, None, out);
        self.check_all(finite, points, t, out)
    }

    /// The error for the first non-finite value, if the evaluation found one.
    fn check_all(&self, finite: bool, points: &[[f64; 2]], t: f64, out: &[f64]) -> Result<()> {
        let m = self.exprs.len();
        if finite {
            return Ok(());
        }
        if let Some(i) = out.iter().position(|v| !v.is_finite()) {
            check(&self.exprs[i % m], out[i], points[i / m], t)?;
        }
        Ok(())
    }

    /// The set bound to fixed points: what depends on x, y only is evaluated now, once.
    pub fn bind(self, points: Vec<[f64; 2]>) -> BoundSet {
        let cache = self.program.fill_cache(&points);
        BoundSet { set: self, points, cache }
    }
}

/// An [`ExprSet`] at fixed points (quadrature points), evaluated at many times: the subexpressions that
/// depend on x, y but not t are computed once, when bound, and read at every time. Same values as
/// [`ExprSet::eval`] at those points (the same operations, done earlier).
#[derive(Clone, Debug)]
pub struct BoundSet {
    set: ExprSet,
    points: Vec<[f64; 2]>,
    cache: Vec<f64>,
}

impl BoundSet {
    /// The points.
    pub fn points(&self) -> &[[f64; 2]] {
        &self.points
    }

    /// As [`ExprSet::eval`] at the bound points.
    pub fn eval(&self, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let finite = self.set.program.eval(&self.points, t, Some(&self.cache), out);
        self.set.check_all(finite, &self.points, t, out)
    }

    /// As [`BoundSet::eval`] at the points `start..start + n` only, on this thread; `start` must be a
    /// multiple of [`program::LANES`](super::program::LANES). Same values as the whole evaluation.
    pub fn eval_range(&self, start: usize, n: usize, t: f64, out: &mut Vec<f64>) -> Result<()> {
        let finite = self.set.program.eval_range(&self.points, start, n, t, &self.cache, out);
        self.set.check_all(finite, &self.points[start..start + n], t, out)
    }
}

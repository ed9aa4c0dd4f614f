//! The symbolic half of the Cholesky factorisation ([`super::factor`]): the fill-reducing ordering
//! with the unknowns ordered last moved to its end, and the structure of L. It needs only K's pattern,
//! so `stepping` computes it while K's values are assembled.

use super::dissect::coordinate_dissection;
use super::ordering::{amd_order, nested_dissection, Graph};
use crate::error::{Error, Result};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::SymbolicSparseColMatRef;
use faer::Side;

/// The symbolic factorisation of a sparsity pattern: the ordering (fill-reducing, with the unknowns
/// `last` moved to its end) and the structure of L. It needs only K's pattern, so it is computed
/// while K's values are assembled ([`Factor::numeric`] then fills it).
pub struct Symbolic {
    pub(super) symbolic: SymbolicCholesky<usize>,
    pub(super) fwd: Vec<usize>,
    pub(super) last: Vec<usize>,
    /// Entries of the pattern (the matrix factorised must have the same pattern).
    pub(super) pattern_nnz: usize,
}

impl Symbolic {
    /// The symbolic factorisation of the symmetric `pattern` (both triangles stored) with the
    /// fill-reducing ordering `base` (position → unknown, a permutation; from [`fill_order`]) and the
    /// distinct unknowns `last` moved to its end, in the given order.
    pub fn new(pattern: SymbolicSparseColMatRef<'_, usize>, last: &[usize], base: Vec<usize>) -> Result<Symbolic> {
        let n = pattern.nrows();
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        if base.len() != n || !is_permutation(&base) {
            return Err(Error::Linear(
                "internal: the fill-reducing ordering is not a permutation of the unknowns".into(),
            ));
        }
        let mut is_last = vec![false; n];
        for &i in last {
            if i >= n || std::mem::replace(&mut is_last[i], true) {
                return Err(Error::Linear(format!("unknown {i} cannot be ordered last (out of range or repeated)")));
            }
        }
        let fwd: Vec<usize> = base.into_iter().filter(|&i| !is_last[i]).chain(last.iter().copied()).collect();
        let mut inv = vec![0usize; n];
        for (new, &old) in fwd.iter().enumerate() {
            inv[old] = new;
        }
        let ordering = SymmetricOrdering::Custom(PermRef::new_checked(&fwd, &inv, n));
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, ordering, params)
            .map_err(|e| Error::Linear(format!("symbolic Cholesky failed: {e:?}")))?;
        Ok(Symbolic { symbolic, fwd, last: last.to_vec(), pattern_nnz: pattern.compute_nnz() })
    }

    /// Entries of L (supernodal blocks included).
    pub fn len_val(&self) -> usize {
        self.symbolic.len_val()
    }
}

/// The fill-reducing ordering of the unknowns of `graph` (position → unknown): nested dissection when
/// `nested` (falling back to AMD where METIS cannot be used), else AMD. See [`super::ordering`].
pub fn fill_order(graph: &Graph, nested: bool) -> Result<Vec<usize>> {
    fill_order_at(graph, None, nested)
}

/// As [`fill_order`], with the nested dissection by coordinate bisection of the vertices at `points`
/// ([`super::dissect`]) instead of METIS's when they are given (and fit the graph).
pub fn fill_order_at(graph: &Graph, points: Option<&[[f64; 2]]>, nested: bool) -> Result<Vec<usize>> {
    if nested {
        if let Some(order) = points.and_then(|p| coordinate_dissection(graph, p)) {
            return Ok(graph.expand(order.into_iter()));
        }
    }
    match if nested { nested_dissection(graph) } else { None } {
        Some((fwd, _)) => Ok(fwd),
        None => amd_order(graph, CholeskySymbolicParams::default().amd_params),
    }
}

fn is_permutation(p: &[usize]) -> bool {
    let mut seen = vec![false; p.len()];
    p.iter().all(|&i| i < p.len() && !std::mem::replace(&mut seen[i], true))
}

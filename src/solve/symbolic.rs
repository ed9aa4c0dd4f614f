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
use faer::{Par, Side};

/// The symbolic factorisation of a sparsity pattern: the ordering (fill-reducing, with the unknowns
/// `last` moved to its end) and the structure of L. It needs only K's pattern, so it is computed
/// while K's values are assembled ([`Factor::numeric`] then fills it).
pub struct Symbolic {
    pub(super) symbolic: SymbolicCholesky<usize>,
    pub(super) fwd: Vec<usize>,
    pub(super) last: Vec<usize>,
    /// Entries of the pattern (the matrix factorised must have the same pattern).
    pub(super) pattern_nnz: usize,
    /// How the fill-reducing ordering was made, as a run reports it ("given" unless named).
    pub(super) ordering: &'static str,
}

impl Symbolic {
    /// The symbolic factorisation of the symmetric `pattern` (its lower triangle read: the lower
    /// triangle alone or both triangles stored, and the matrix factorised the same) with the
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
        Ok(Symbolic { symbolic, fwd, last: last.to_vec(), pattern_nnz: pattern.compute_nnz(), ordering: "given" })
    }

    /// Entries of L (supernodal blocks included).
    pub fn len_val(&self) -> usize {
        self.symbolic.len_val()
    }

    /// The same, its ordering named `ordering` (reported by runs: [`super::factor::Factor::ordering`]).
    pub fn ordered_by(self, ordering: &'static str) -> Symbolic {
        Symbolic { ordering, ..self }
    }

    /// Bytes the numeric factorisation allocates: L's values and its scratch.
    fn need_of(symbolic: &SymbolicCholesky<usize>) -> u64 {
        let scratch = symbolic.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default());
        (symbolic.len_val() as u64).saturating_mul(8).saturating_add(scratch.unaligned_bytes_required() as u64)
    }

    /// Whether the numeric factorisation, and `more` bytes the caller will allocate beside it, fit in the
    /// memory this machine has now (MemAvailable; `true` where the machine does not say).
    pub fn fits(&self, more: u64) -> bool {
        Symbolic::fits_with(&self.symbolic, more).is_ok()
    }

    /// Refuse a factor whose values and scratch (and `more` bytes beside them) do not fit in the memory
    /// this machine has now: L's pages are mapped lazily, so an allocation that does not fit would
    /// succeed and the process be killed later. The sizes are exact once the symbolic factorisation is
    /// done, where the pre-run estimate (`scene::budget`) is a fit.
    pub(super) fn fits_with(symbolic: &SymbolicCholesky<usize>, more: u64) -> Result<()> {
        let need = Symbolic::need_of(symbolic).saturating_add(more);
        refuse_beyond(need, crate::machine::available_memory(), symbolic.nrows(), symbolic.len_val())
    }
}

/// `TooLarge` when `need` bytes exceed `have` (a factor of `n` unknowns and `len_val` entries).
fn refuse_beyond(need: u64, have: Option<u64>, n: usize, len_val: usize) -> Result<()> {
    match have {
        Some(have) if need > have => Err(Error::TooLarge {
            what: "memory for the Cholesky factor",
            need,
            have,
            limit: "is available on this machine",
            hint: format!(
                "{n} unknowns, {len_val} entries in the factor: use a coarser mesh (--refine) or a machine with more memory"
            ),
        }),
        _ => Ok(()),
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

#[cfg(test)]
mod tests {
    use super::refuse_beyond;
    use crate::error::Error;

    /// The system shall refuse a factor larger than the memory there is, naming the sizes, and accept it
    /// when it fits or when the machine does not say what it has.
    #[test]
    fn a_factor_beyond_the_memory_is_refused() {
        assert!(refuse_beyond(10, Some(10), 4, 1).is_ok());
        assert!(refuse_beyond(10, None, 4, 1).is_ok());
        match refuse_beyond(11, Some(10), 4, 1) {
            Err(Error::TooLarge { need: 11, have: 10, hint, .. }) => assert!(hint.contains("4 unknowns")),
            other => panic!("expected TooLarge, got {other:?}"),
        }
    }
}

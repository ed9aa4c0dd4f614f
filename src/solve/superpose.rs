//! Solving by superposition when the loads of all time nodes span a low-dimensional space.
//!
//! Many scenes load the body proportionally (Example 5.1: g(x, t) = t g₁(x)) or by a few time-modulated
//! patterns. At set-up the loads l(t₀), …, l(t_N) are orthonormalised in time order (classical Gram–Schmidt,
//! applied twice); if every l(tₙ) lies in the span of at most [`MAX_RANK`] vectors b_j (residual
//! ≤ [`SPAN_TOL`] ‖l(tₙ)‖), the run stores w_j = K⁻¹b_j and coefficients cₙⱼ, and each step gets
//! u_f = K⁻¹l(tₙ) = Σ_j cₙⱼ w_j without a triangular solve. Otherwise nothing is kept and every step
//! assembles and solves. The basis depends only on the scene, so a resumed run computes the same numbers.
//! The orthogonalisation works on the loads' support only (the boundary unknowns when there is no body
//! force), so its cost is O(N · support) rather than O(N · unknowns).
//! When every load term separates into time factors times space patterns (`fem::loads`), the patterns
//! are orthonormalised instead ([`LoadBasis::build`]): no load is formed at a node, and the rank is that
//! of the patterns.
//!
//! The nodes are orthogonalised in van der Corput order (0, N, N/2, N/4, 3N/4, …), not in time order.
//! In time order a load that is proportional for a while and then turns (mms_stop: rank 4 in all)
//! picks up its later patterns from nodes just after the turn, where they are a tiny part of the load
//! (3e-4 relative at t = 0.375), and classical Gram–Schmidt then loses digits: the residual of the
//! later nodes grew from 1e-15 to 1e-13 and the exactly rank-4 load was refused after 41 of 65
//! assemblies at refine 5. Spread nodes meet every pattern where it is large (residuals ≤ 2e-16 there),
//! and loads that need more than [`MAX_RANK`] patterns are refused within a few nodes.

use super::cholesky::Factor;
use crate::error::{Error, Result};
use crate::fem::loads::Loads;
use crate::sparse::dot;
use std::borrow::Cow;

/// Largest number of load patterns handled by superposition.
pub const MAX_RANK: usize = 4;
/// Relative residual below which a load counts as in the span (a few hundred ulps of the load).
pub const SPAN_TOL: f64 = 1e-13;

/// ‖l‖² stays in the normal range of f64, so the unscaled computation is exact to rounding, when the
/// largest entry of l is in [2^-450, 2^450] (about 1e±135) — every load of a physical scene in any units.
const SAFE_EXP: i32 = 450;

/// (k, l̂) with l = 2^k l̂: k = 0 and l̂ = l (borrowed, bit-identical arithmetic) when the largest entry is
/// within 2^±SAFE_EXP or zero, else the power of two that brings it to [1, 2).
fn unit_scale(l: &[f64]) -> (i32, Cow<'_, [f64]>) {
    let m = l.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    if m == 0.0 || !m.is_finite() || (m >= pow2(-SAFE_EXP) && m <= pow2(SAFE_EXP)) {
        return (0, Cow::Borrowed(l));
    }
    let k = m.log2().floor() as i32;
    (k, Cow::Owned(l.iter().map(|v| pow2_scale(*v, -k)).collect()))
}

/// 2^k for |k| ≤ 1023.
fn pow2(k: i32) -> f64 {
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// v · 2^k, exact unless the result leaves the normal range (two steps, so |k| may reach 2100).
fn pow2_scale(v: f64, k: i32) -> f64 {
    let h = k / 2;
    v * pow2(h) * pow2(k - h)
}

/// 0, …, m − 1 in van der Corput order: the ends, then the midpoint, then the quarter points, … (each
/// index once).
fn spread(m: usize) -> impl Iterator<Item = usize> {
    let last = m.saturating_sub(1);
    let levels = usize::BITS - last.leading_zeros() + 1;
    let mut seen = vec![false; m];
    // level k: the odd multiples j·last/2^k, rounded; from 2^k ≥ last on they cover every index
    let dyadic =
        (1..=levels).flat_map(move |k| (1..1usize << k).step_by(2).map(move |j| (j * last + (1 << (k - 1))) >> k));
    [0, last].into_iter().chain(dyadic).filter(move |&i| i < m && !std::mem::replace(&mut seen[i], true))
}

/// The coordinates of `l` in the orthonormal vectors `b` (classical Gram–Schmidt, applied twice), `b`
/// extended by the normalised residual when it exceeds [`SPAN_TOL`] ‖l‖; `None` if that would make more
/// than [`MAX_RANK`] vectors. Loads beyond ~1e±135 are scaled by a power of two first (exactly) and their
/// coordinates scaled back.
fn orthogonalise(b: &mut Vec<Vec<f64>>, l: &[f64]) -> Option<Vec<f64>> {
    // l = 2^k l̂ with l̂ of order 1 where ‖l‖² would overflow or underflow (loads beyond ~1e±150):
    // Gram–Schmidt runs on l̂ and the coefficients are scaled back, exactly (powers of two).
    let (k, scaled) = unit_scale(l);
    let norm = dot(&scaled, &scaled).sqrt();
    let mut r = scaled.into_owned();
    let mut c = vec![0.0; b.len()];
    for _ in 0..2 {
        for (j, bj) in b.iter().enumerate() {
            let p = dot(bj, &r);
            c[j] += p;
            r.iter_mut().zip(bj).for_each(|(ri, bi)| *ri -= p * bi);
        }
    }
    let rn = dot(&r, &r).sqrt();
    if rn > SPAN_TOL * norm {
        if b.len() == MAX_RANK {
            return None;
        }
        r.iter_mut().for_each(|v| *v /= rn);
        b.push(r);
        c.push(rn);
    }
    if k != 0 {
        c.iter_mut().for_each(|v| *v = pow2_scale(*v, k));
    }
    Some(c)
}

/// `c` if every coefficient is finite, else the error that the loads at `t` are too large for f64.
fn check_range(c: Vec<f64>, t: f64) -> Result<Vec<f64>> {
    match c.iter().find(|v| !v.is_finite()) {
        Some(bad) => Err(Error::Linear(format!(
            "t = {t}: the load's coefficient {bad} is beyond the range of f64: the loads are too large"
        ))),
        None => Ok(c),
    }
}

/// Orthonormal load patterns, their responses and the coefficients of every time node.
pub struct LoadBasis {
    /// Orthonormal patterns on the loads' support (see `Loads::support`), support indices.
    b: Vec<Vec<f64>>,
    support: Vec<usize>,
    /// Responses K⁻¹b_j on all unknowns.
    responses: Vec<Vec<f64>>,
    coef: Vec<Vec<f64>>,
}

impl LoadBasis {
    /// Try to build the basis; `None` if the loads need more than [`MAX_RANK`] patterns.
    ///
    /// When the loads of the nodes are refused, `assembled` receives those assembled on the way (at most
    /// [`MAX_RANK`] + 1, node and load on the support), for the steps at those nodes to use instead of
    /// assembling them again; otherwise it is left empty.
    pub fn build(
        loads: &Loads,
        times: &[f64],
        factor: &Factor,
        assembled: &mut Vec<(usize, Vec<f64>)>,
    ) -> Result<Option<LoadBasis>> {
        assembled.clear();
        if let Some(basis) = Self::from_patterns(loads, times, factor)? {
            return Ok(Some(basis));
        }
        let mut b: Vec<Vec<f64>> = Vec::new();
        let mut coef = vec![Vec::new(); times.len()];
        for n in spread(times.len()) {
            let t = times[n];
            let mut l = Vec::new();
            loads.assemble_on_support(t, &mut l)?;
            let c = orthogonalise(&mut b, &l);
            assembled.push((n, l));
            let Some(c) = c else {
                return Ok(None);
            };
            coef[n] = check_range(c, t)?;
        }
        assembled.clear();
        Ok(Some(Self::with_responses(loads, b, coef, factor)))
    }

    /// When every load term is separated (l(t) = Σ_j τ_j(t) P_j, `fem::loads`), the patterns P_j are
    /// orthonormalised instead of the loads of the nodes, P_j = Σ_i R_ji b_i, and cₙ = Σ_j τ_j(tₙ) R_j:
    /// no load is formed at a node. `None` (the nodes' route decides) when there are no patterns or more than
    /// [`MAX_RANK`] independent ones (the loads at the nodes may still span fewer).
    fn from_patterns(loads: &Loads, times: &[f64], factor: &Factor) -> Result<Option<LoadBasis>> {
        let Some(patterns) = loads.separated().filter(|p| !p.is_empty()) else {
            return Ok(None);
        };
        let mut b: Vec<Vec<f64>> = Vec::new();
        let mut r = Vec::new();
        for p in patterns {
            let Some(c) = orthogonalise(&mut b, p) else {
                return Ok(None);
            };
            r.push(c);
        }
        let mut coef = Vec::with_capacity(times.len());
        for &t in times {
            let mut c = vec![0.0; b.len()];
            for (tau, rj) in loads.time_factors(t)?.into_iter().zip(&r) {
                c.iter_mut().zip(rj).for_each(|(ci, x)| *ci += tau * x);
            }
            coef.push(check_range(c, t)?);
        }
        Ok(Some(Self::with_responses(loads, b, coef, factor)))
    }

    /// The basis with its responses K⁻¹b_j: one solve with rank right-hand sides (the factor is read once).
    fn with_responses(loads: &Loads, b: Vec<Vec<f64>>, coef: Vec<Vec<f64>>, factor: &Factor) -> LoadBasis {
        let mut x = Vec::new();
        let mut col = Vec::new();
        for bj in &b {
            loads.expand(bj, &mut col);
            x.extend_from_slice(&col);
        }
        let n = col.len();
        let responses = if n == 0 {
            vec![vec![]; b.len()]
        } else {
            factor.solve_many(&mut x, b.len());
            x.chunks_exact(n).map(|c| c.to_vec()).collect()
        };
        LoadBasis { b, support: loads.support().to_vec(), responses, coef }
    }

    fn combine(vs: &[Vec<f64>], c: &[f64], n: usize, out: &mut Vec<f64>) {
        out.clear();
        out.resize(n, 0.0);
        for (v, &cj) in vs.iter().zip(c) {
            out.iter_mut().zip(v).for_each(|(o, x)| *o += cj * x);
        }
    }

    /// l(tₙ) = Σ_j cₙⱼ b_j.
    pub fn load(&self, n: usize, dofs: usize, out: &mut Vec<f64>) {
        let mut on_support = Vec::new();
        Self::combine(&self.b, &self.coef[n], self.support.len(), &mut on_support);
        out.clear();
        out.resize(dofs, 0.0);
        for (&k, v) in self.support.iter().zip(on_support) {
            out[k] = v;
        }
    }

    /// Entries `idx` of K⁻¹ l(tₙ): O(rank · idx.len()).
    pub fn response_at(&self, n: usize, idx: &[usize]) -> Vec<f64> {
        idx.iter().map(|&k| self.responses.iter().zip(&self.coef[n]).map(|(w, c)| c * w[k]).sum()).collect()
    }

    /// e = Rᵀl(tₙ) = Σ_j cₙⱼ Rᵀb_j for the rigid motions R of a floating body.
    pub fn net(&self, n: usize, kernel: &super::kernel::Kernel) -> Vec<f64> {
        let mut e = vec![0.0; kernel.len()];
        for (bj, c) in self.b.iter().zip(&self.coef[n]) {
            e.iter_mut().zip(kernel.net(&self.support, bj)).for_each(|(ei, v)| *ei += c * v);
        }
        e
    }

    /// K⁻¹ l(tₙ) = Σ_j cₙⱼ w_j.
    pub fn response(&self, n: usize, dofs: usize, out: &mut Vec<f64>) {
        Self::combine(&self.responses, &self.coef[n], dofs, out);
    }
}

#[cfg(test)]
mod tests {
    use super::spread;

    #[test]
    fn spread_visits_every_node_once_ends_first() {
        for m in 0..40 {
            let order: Vec<usize> = spread(m).collect();
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..m).collect::<Vec<_>>(), "m = {m}");
        }
        assert_eq!(spread(65).take(5).collect::<Vec<_>>(), [0, 64, 32, 16, 48]);
    }
}

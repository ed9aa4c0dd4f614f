//! Checks of single scene values: positive numbers, expression sizes, uniform time grids (refused before
//! they are allocated when they cannot fit), and the line of a TOML error.

use super::budget;
use crate::error::{Error, Result};

/// Longest accepted expression (characters). The longest generated expression of the repository has
/// ~3,000; parsing time and memory grow faster than the length (10 MB took over a minute and 3.6 GB).
pub const MAX_EXPR_CHARS: usize = 100_000;

/// Refuse expressions longer than [`MAX_EXPR_CHARS`] before they reach the parser.
pub(super) fn sized<'a, const K: usize>(file: &str, key: &str, texts: &'a [String; K]) -> Result<&'a [String; K]> {
    match texts.iter().map(|t| t.len()).max() {
        Some(n) if n > MAX_EXPR_CHARS => Err(Error::scene(
            file,
            key,
            format!("an expression of {n} characters is longer than the {MAX_EXPR_CHARS} accepted"),
        )),
        _ => Ok(texts),
    }
}

pub(super) fn positive_finite(file: &str, key: &str, v: f64) -> Result<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(Error::scene(file, key, format!("must be a positive finite number, got {v}")))
    }
}

/// Bound on the geometric factors of the stiffness entries: (λ+2μ)·|e|²/|T| (elastic) and ρμ·|e|/h
/// (jump) have factors of about 4 on the right isosceles triangles of the structured meshes and of
/// order one on any shape-regular mesh; slivers beyond it are refused as ill-conditioned.
const GEOMETRY: f64 = 10.0;

/// Refuse material data whose stiffness cannot be handled in f64: the set-up forms squares of the
/// entries (the condition estimate's ‖Kx‖², the energy a_h(u, u)), so the entries must lie within the
/// square root of f64's normal range, [1.5e-154, 1.3e154] (E = 1e308 or ρ = 1e300 overflow, E = 5e-324
/// underflows); and the jump term must not be so small or so large against the elastic one (ρ outside
/// [ε, 1/ε], ε = 2.2e-16) that one of the two is lost in the rounding of their sum. Such a K fails its
/// factorisation or its condition estimate, which would otherwise blame the mesh or the Dirichlet parts.
pub(super) fn representable(file: &str, e: f64, nu: f64, rho: f64) -> Result<()> {
    let (top, bottom) = (f64::MAX.sqrt(), f64::MIN_POSITIVE.sqrt());
    let mu = e / (2.0 * (1.0 + nu));
    let stiff = e * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu)); // λ + 2μ
    let largest = stiff.max(rho * mu) * GEOMETRY;
    if largest.is_nan() || largest > top {
        return Err(Error::scene(
            file,
            "material.E, discretisation.rho",
            format!(
                "E = {e:e}, rho = {rho:e}: the stiffness entries (λ+2μ = {stiff:.3e}, ρμ = {:.3e}, times the mesh's \
                 geometric factors) overflow when squared (beyond √(1.8e308) = 1.3e154); give the data in other units \
                 (u scales with load/E)",
                rho * mu
            ),
        ));
    }
    let smallest = mu.min(rho * mu) / GEOMETRY;
    if smallest.is_nan() || smallest < bottom {
        return Err(Error::scene(
            file,
            "material.E, discretisation.rho",
            format!(
                "E = {e:e}, rho = {rho:e}: the stiffness entries (μ = {mu:.3e}, ρμ = {:.3e}, times the mesh's \
                 geometric factors) underflow when squared (below √(2.2e-308) = 1.5e-154); give the data in other units",
                rho * mu
            ),
        ));
    }
    if !(f64::EPSILON..=1.0 / f64::EPSILON).contains(&rho) {
        return Err(Error::scene(
            file,
            "discretisation.rho",
            format!(
                "rho = {rho:e} is outside [ε, 1/ε] = [2.2e-16, 4.5e15]: the {} term of the stiffness is below the \
                 rounding of the other (relative ε) and is lost, so K is singular in floating point",
                if rho < 1.0 { "jump (stabilisation)" } else { "elastic" }
            ),
        ));
    }
    Ok(())
}

pub(super) fn uniform_times(file: &str, t: f64, n: usize) -> Result<Vec<f64>> {
    if n == 0 {
        return Err(Error::scene(file, "time.steps", "must be at least 1"));
    }
    // refuse before allocating: a step costs at least its time node and load coefficients in memory
    let need = (n as u64).saturating_add(1).saturating_mul(64);
    let have = budget::available_memory();
    let mut times = Vec::new();
    if have.is_some_and(|h| need > h) || times.try_reserve_exact(n.saturating_add(1)).is_err() {
        return Err(Error::scene(
            file,
            "time.steps",
            format!(
                "{n} steps need about {} of memory for their time nodes alone, more than this machine has",
                crate::error::human(need)
            ),
        ));
    }
    times.extend((0..=n).map(|k| t * k as f64 / n as f64));
    // T/N below the spacing of the floating-point numbers near the nodes (T = 5e-324 with 8 steps gives
    // 0, 0, 0, 0, 0, 5e-324, ...): steps of zero length, refused as a `times` list with repeated nodes is
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        return Err(Error::scene(
            file,
            "time",
            format!(
                "T = {t:e} in {n} steps: the time nodes collapse (t[{k}] = {:e}, t[{}] = {:e}): the step T/steps = \
                 {:e} is below the resolution of floating point there (underflow); use a larger T or fewer steps",
                times[k],
                k + 1,
                times[k + 1],
                t / n as f64
            ),
        ));
    }
    Ok(times)
}

/// "line L: key": where a TOML error is, with the key the line assigns (if it assigns one).
pub(super) fn at_line(text: &str, line: usize) -> String {
    let key = text.lines().nth(line.saturating_sub(1)).and_then(|l| l.split_once('=')).map(|(k, _)| k.trim());
    match key {
        Some(k) if !k.is_empty() && !k.starts_with('#') => format!("line {line}: {k}"),
        _ => format!("line {line}"),
    }
}

pub(super) fn line_of(text: &str, byte: usize) -> usize {
    text[..byte.min(text.len())].matches('\n').count() + 1
}

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
    Ok(times)
}

pub(super) fn line_of(text: &str, byte: usize) -> usize {
    text[..byte.min(text.len())].matches('\n').count() + 1
}

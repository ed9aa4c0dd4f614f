//! Value parsers of the numeric options. The options that take them accept values starting with `-`
//! (`allow_negative_numbers` / `allow_hyphen_values`), so that `--steps -5` reaches the parser, which
//! names the rule; without that clap reports "unexpected argument '-5' found", naming neither the
//! option nor what it takes. clap prefixes the message with the option's name. (`--tol` and `plan --target`
//! take any number here; the library refuses non-positive ones, naming the option.)

use tresca_cr::scene::budget::parse_size;
use tresca_cr::study::Level;

/// A whole number ≥ 0 (`--steps`, `--frame-every`: their lower bounds are checked with the scene).
pub fn count(text: &str) -> Result<usize, String> {
    text.trim().parse().map_err(|_| format!("`{text}`: expected a whole number ≥ 0"))
}

/// A number of uniform refinements, 0 to 12 (as `mesh.refine`).
pub fn refine(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(k) if k <= 12 => Ok(k),
        Ok(k) => Err(format!("{k} refinements is beyond any machine (at most 12)")),
        Err(_) => Err(format!("`{text}`: expected a whole number of refinements from 0 to 12")),
    }
}

/// A finite number ≥ 0 (`--commit-interval`, seconds).
pub fn non_negative(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("`{text}`: expected a finite number ≥ 0")),
    }
}

/// A size ≥ 0 such as 800M or 16G (`--max-memory`, `--max-disk`).
pub fn size(text: &str) -> Result<u64, String> {
    if text.trim().starts_with('-') {
        return Err(format!("`{text}`: a size cannot be negative; expected e.g. 800M, 16G or a number of bytes"));
    }
    parse_size(text)
}

/// A study level `refine:steps` (refine 0 to 12, steps ≥ 1).
pub fn level(text: &str) -> Result<Level, String> {
    let l: Level = text.parse().map_err(|e| format!("{e} (refine is a whole number from 0 to 12, steps one ≥ 1)"))?;
    refine(&l.refine.to_string())?;
    Ok(l)
}

/// Dörfler's θ, a number in (0, 1] (`adapt --theta`).
pub fn theta(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 1.0 => Ok(v),
        _ => Err(format!("`{text}`: expected Dörfler's θ, a number in (0, 1] (the share of η² marked)")),
    }
}

/// A whole number ≥ 1 (`adapt --levels`: the starting mesh is level 0, so one level is the least).
pub fn at_least_one(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(k) if k >= 1 => Ok(k),
        _ => Err(format!("`{text}`: expected a whole number ≥ 1")),
    }
}

/// A finite number > 0 (`adapt --target`, an energy-norm error).
pub fn positive(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{text}`: expected a finite number > 0")),
    }
}

/// A bisection generation, 0 to 24 (`adapt --reference`: two bisections halve h, so 24 is `refine` 12).
pub fn generation(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(g) if g <= 24 => Ok(g),
        Ok(g) => Err(format!("generation {g} is beyond any machine (at most 24, as 12 uniform refinements)")),
        Err(_) => Err(format!("`{text}`: expected a whole number of bisection generations from 0 to 24")),
    }
}

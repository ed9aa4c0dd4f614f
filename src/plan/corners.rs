//! The plan's order bound min(1, α_min) with each contact corner's exponent taken from the states the
//! pilot runs went through there (`docs/plan.md`, "The order bound").
//!
//! A contact side sticks (clamped tangentially: the exponent of a clamped side), slips (a sliding side) or
//! separates (a free side). `check` knows none of this and bounds a contact corner over stick and slip.
//! The pilots do: every pilot level records, over all its steps, the states of the Γ_C edges at each
//! vertex (`study::contact_states`); a corner takes the union over all the pilot levels run so far, and
//! its exponent is the smallest over the conditions in that union — conservative over the states seen. A
//! corner where no pilot level saw a state keeps the bound over stick and slip.
//!
//! A corner whose exponent so taken is at most `fem::singular::FLOOR_EXPONENT` gives an error floor, not a
//! rate (a polygonised curve's vertex where the pilots saw slip on both sides: the slip paradox); the
//! plan is then refused ([`floor_refusal`], `docs/plan.md`).

use crate::error::Result;
use crate::fem::singular::{of_scene_observed, uniform_order, Singularity};
use crate::fem::williams::Side;
use crate::scene::Scene;
use crate::study::contact_states::{SEPARATED, SLIP, STICK};
use crate::study::LevelResult;

/// A pilot vertex is the corner when within this share of the level's mesh size of it (refinement keeps
/// the corner's coordinates up to rounding; the next vertex is a whole edge away).
const SAME_POINT: f64 = 1e-6;

/// The conditions of the states in `bits` (`study::contact_states`), in the order clamped, sliding, free.
pub fn sides_of_states(bits: u8) -> Vec<Side> {
    [(STICK, Side::Clamped), (SLIP, Side::Sliding), (SEPARATED, Side::Free)]
        .into_iter()
        .filter(|(b, _)| bits & b != 0)
        .map(|(_, s)| s)
        .collect()
}

/// The states the levels saw at `point` (0: none seen there).
fn states_at(levels: &[&LevelResult], point: [f64; 2]) -> u8 {
    let mut bits = 0;
    for l in levels {
        let near = |q: &[f64; 2]| (q[0] - point[0]).hypot(q[1] - point[1]) <= SAME_POINT * l.h;
        bits |= l.contact_states.iter().filter(|(q, _)| near(q)).fold(0, |a, (_, b)| a | b);
    }
    bits
}

/// min(1, α_min) of the scene with the contact corners' conditions from `levels` (module doc), and one line
/// per contact corner saying which conditions were used.
pub fn order_limit(scene: &Scene, levels: &[&LevelResult]) -> Result<(f64, Vec<String>)> {
    let points = observed(scene, levels)?;
    let lines = points.iter().filter_map(|s| describe(scene, levels, s)).collect();
    Ok((uniform_order(&points), lines))
}

/// The scene's singular points with the contact corners' conditions from `levels`.
fn observed(scene: &Scene, levels: &[&LevelResult]) -> Result<Vec<Singularity>> {
    let seen = |p: [f64; 2]| Some(sides_of_states(states_at(levels, p))).filter(|s| !s.is_empty());
    of_scene_observed(scene, seen)
}

/// Why no plan can be promised when a point, its contact sides' conditions from `levels`, gives an error
/// floor rather than a rate (`fem::singular::FLOOR_EXPONENT`), naming the points; `None` without one.
/// The pilots' estimates measure the differences between levels, which the floor's energy, at scales no
/// mesh resolves, never enters: a plan would promise the error relative to the polygon problem short of
/// a floor of about c√(2μαω) it cannot bound (`docs/plan.md`).
pub fn floor_refusal(scene: &Scene, levels: &[&LevelResult]) -> Result<Option<String>> {
    let points = observed(scene, levels)?;
    let floors: Vec<&Singularity> = points.iter().filter(|s| s.floor()).collect();
    let Some(worst) = floors.iter().map(|s| s.uniform_order()).reduce(f64::min) else { return Ok(None) };
    let at: Vec<String> = floors
        .iter()
        .map(|s| {
            format!(
                "({:.4}, {:.4}) {:.2}° {}–{}",
                s.point[0],
                s.point[1],
                s.angle.to_degrees(),
                s.sides[0].name(),
                s.sides[1].name()
            )
        })
        .collect();
    Ok(Some(format!(
        "the error has a floor, not a rate: at {} point(s) the conditions the pilots saw (where they saw none, the bound over stick and slip) give α ≤ \
         {worst:.4} (at most \
         {:.4}: less than 2× over every refinement), {} — at a vertex of angle ω < π between two sliding sides α = \
         π/ω − 1, the slip paradox of a polygonised curve, whose singular part puts an energy 2μc²αω R^(2α) within R \
         of the vertex at scales no mesh resolves: an error floor of about c√(2μαω) (c the tangential displacement \
         there) that no refinement of this mesh lowers and no pilot estimate sees. No refinement can be promised to \
         reach the target; refine the curve itself (a finer mesh file with every vertex on the curve) and compare \
         the levels with `study`",
        floors.len(),
        crate::fem::singular::FLOOR_EXPONENT,
        at.join(", ")
    )))
}

/// The line of a contact corner (`None` for any other point).
fn describe(scene: &Scene, levels: &[&LevelResult], s: &Singularity) -> Option<String> {
    use crate::scene::PartKind;
    if !s.parts.iter().any(|&q| matches!(scene.parts[q].kind, PartKind::Contact(_))) {
        return None;
    }
    let names = s.parts.map(|q| scene.parts[q].name.as_str());
    let alpha = s.alpha.map_or("none below 1".to_string(), |a| format!("{:.4}", a.re));
    let how = if s.observed {
        let states = [(STICK, "stick"), (SLIP, "slip"), (SEPARATED, "separated")]
            .into_iter()
            .filter(|(b, _)| states_at(levels, s.point) & b != 0)
            .map(|(_, n)| n)
            .collect::<Vec<_>>()
            .join(", ");
        format!("the pilots saw {states} there")
    } else {
        "no pilot state there: the bound over stick and slip".to_string()
    };
    Some(format!(
        "contact corner ({:.4}, {:.4}) {}–{}: {how}; {}–{}, α = {alpha}",
        s.point[0],
        s.point[1],
        names[0],
        names[1],
        s.sides[0].name(),
        s.sides[1].name()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The states map to the conditions of `fem::williams`: stick clamped, slip sliding, separated free.
    #[test]
    fn states_map_to_conditions() {
        assert_eq!(sides_of_states(STICK), vec![Side::Clamped]);
        assert_eq!(sides_of_states(SLIP | SEPARATED), vec![Side::Sliding, Side::Free]);
        assert!(sides_of_states(0).is_empty());
    }
}

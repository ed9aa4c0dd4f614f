//! `check`'s singular exponents: one line per polygon corner and change of condition, with the leading
//! exponent α of plane-strain elasticity there ([`tresca_cr::fem::singular`]), and the orders that
//! follow from the smallest: min(1, Re α) in h under uniform refinement, N^(−1/2) in the unknowns N under
//! adaptive refinement. Points whose α gives an error floor rather than a rate
//! ([`tresca_cr::fem::singular::FLOOR_EXPONENT`]: a polygonised curve's vertices between sliding sides,
//! the slip paradox) are marked and counted apart.

use super::summary::{Singular, SingularPoint};
use tresca_cr::fem::singular::{uniform_order, Singularity, FLOOR_EXPONENT};
use tresca_cr::scene::{Part, PartKind};

/// The human lines (the first a header) and the `--json` record.
pub fn describe(points: &[Singularity], parts: &[Part]) -> (Vec<String>, Singular) {
    let mut lines = Vec::new();
    let order = uniform_order(points);
    lines.push(format!(
        "corners    {} corner(s) and change(s) of condition; uniform refinement reaches O(h^{order:.4}) in energy, \
         adaptive O(N^-0.5)",
        points.len()
    ));
    let floors = points.iter().filter(|s| s.floor()).count();
    if floors > 0 {
        lines.push(format!(
            "           {floors} of them with α ≤ {FLOOR_EXPONENT:.4} (polygonised curve: slip-paradox floor): an error \
             floor of about c√(2μαω) (c the tangential displacement there), not a rate; `plan` refuses the scene where \
             its pilots see slip on both sides of one"
        ));
    }
    let mut json = Singular { points: Vec::new(), uniform_order: order, adaptive_order: 0.5 };
    for s in points {
        let names = s.parts.map(|p| parts[p].name.as_str());
        let alpha = match s.alpha {
            None => "none below 1".to_string(),
            Some(a) if a.im == 0.0 => format!("{:.6}", a.re),
            Some(a) => format!("{:.6} ± {:.6}i", a.re, a.im),
        };
        let contact = s.parts.iter().any(|&p| matches!(parts[p].kind, PartKind::Contact(_)));
        let how =
            if contact { "  (contact: the bound over stick and slip; `plan` uses its pilots' states)" } else { "" };
        let floor = if s.floor() { "  polygonised curve: slip-paradox floor" } else { "" };
        lines.push(format!(
            "           ({:.6}, {:.6}) angle {:>7.2}°  {}–{} ({}–{})  alpha = {alpha}{floor}{how}",
            s.point[0],
            s.point[1],
            s.angle.to_degrees(),
            names[0],
            names[1],
            s.sides[0].name(),
            s.sides[1].name()
        ));
        json.points.push(SingularPoint {
            x: s.point[0],
            y: s.point[1],
            angle: s.angle,
            parts: names.map(str::to_string),
            sides: s.sides.map(|x| x.name().to_string()),
            alpha: s.alpha.map(|a| a.re),
            alpha_imag: s.alpha.map(|a| a.im),
            floor: s.floor(),
        });
    }
    (lines, json)
}

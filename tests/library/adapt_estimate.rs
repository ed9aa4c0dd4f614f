//! The adaptive loop's error estimate (src/adapt/estimate.rs): η calibrated along the sequence against a
//! Richardson estimate in the unknowns at the optimal rate N^(−1/2), held to an effectivity (estimate / true
//! error) in [0.8, 1.25] past the first four levels, and the loop stopped by it.

use crate::common;

use common::scene;
use tresca_cr::adapt::estimate::TRUSTED_FROM;
use tresca_cr::adapt::{adapt, Options, Row};

/// The band of the estimate's effectivity (issue 42): the planner's adaptive route stops at an estimate
/// of 0.8 T (`plan::adaptive::ESTIMATE_SHARE`), so a true error of at most T needs estimate/error ≥ 0.8.
const BAND: (f64, f64) = (0.8, 1.25);

fn rows(case: &str, levels: usize) -> Vec<Row> {
    adapt(&scene(case), &Options::levels(levels, 0.5), |_| {}).unwrap().rows
}

fn effectivities(rows: &[Row]) -> Vec<(usize, f64)> {
    rows.iter()
        .filter(|r| r.level >= TRUSTED_FROM)
        .map(|r| (r.level, r.estimate.expect("an estimate from level 1 on") / r.error.expect("[exact]")))
        .collect()
}

/// The system shall estimate the energy error of every adaptive level past the first four within
/// [0.8, 1.25] of the true error on the corner-singular `mms_lshape` (λ = 0.5445 at the re-entrant corner)
/// and on `mms_data_front` (Dirichlet data and an advancing slip front), over 12 levels (to about 10,000
/// and 3,400 unknowns); the rule's constants (rate ½, window 8) come from the theory, not from these
/// errors, so the test can fail (the distance to the next level, which adds the coarse level's jumps,
/// gives 1.2–1.5 on the same levels).
#[test]
fn estimate_effectivity_is_near_one_past_the_first_four_levels() {
    for case in ["verification/cases/mms_lshape.toml", "verification/cases/mms_data_front.toml"] {
        let r = rows(case, 12);
        assert!(r[0].estimate.is_none() && r[1..].iter().all(|x| x.estimate.is_some()), "{case}");
        let eff = effectivities(&r);
        assert_eq!(eff.len(), 12 - TRUSTED_FROM, "{case}");
        assert!(eff.iter().all(|&(_, e)| e >= BAND.0 && e <= BAND.1), "{case}: {eff:?}");
    }
}

/// The system shall stop the loop at the first level from `TRUSTED_FROM` on whose estimate is at most
/// the target given (`adapt --target`: the estimate, not the indicator η), and not before.
#[test]
fn loop_stops_at_its_target_estimate() {
    let s = scene("verification/cases/mms_lshape.toml");
    let full = rows("verification/cases/mms_lshape.toml", 10);
    let goal = full[7].estimate.unwrap();
    let stop = full.iter().position(|r| r.level >= TRUSTED_FROM && r.estimate.unwrap() <= goal).unwrap();
    let got = adapt(&s, &Options { target: Some(goal), ..Options::levels(20, 0.5) }, |_| {}).unwrap();
    assert_eq!(got.rows.len(), stop + 1);
    assert_eq!(got.rows[stop].estimate.map(f64::to_bits), full[stop].estimate.map(f64::to_bits));
}

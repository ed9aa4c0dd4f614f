//! Factor once per mesh (issue 32): the levels of a study and the pilots of a plan that share a mesh
//! share one assembly and one numeric factorisation of K. Counted, not timed, so these cannot flake.

use crate::common;

use common::scene;
use tresca_cr::plan::pilot::Quantity;
use tresca_cr::plan::{plan_with_cache, Options};
use tresca_cr::stepping::Problem;
use tresca_cr::study::{run_study, Level, LevelResult};

fn levels(text: &str) -> Vec<Level> {
    text.split(',').map(|l| l.parse().unwrap()).collect()
}

/// Requirement: the system shall factorise K once per mesh in a study: a 4-level k-study on one mesh
/// factorises once, a study over two meshes twice, and every level reports whether it factorised.
#[test]
fn a_study_factorises_once_per_mesh() {
    let s = scene("verification/cases/mms_stop.toml");
    let k = run_study(&s, &levels("3:4,3:16,3:64,3:256"), None, None, |_| ()).unwrap();
    let f: Vec<bool> = k.levels.iter().map(|r| r.factorised).collect();
    assert_eq!(f, [true, false, false, false], "a k-study: one factorisation");
    assert!(k.levels[1..].iter().all(|r| r.reused_setup > 0.0));
    let hk = run_study(&s, &levels("2:4,2:8,3:8,3:16"), None, None, |_| ()).unwrap();
    let f: Vec<bool> = hk.levels.iter().map(|r| r.factorised).collect();
    assert_eq!(f, [true, false, true, false], "two meshes: two factorisations");
}

/// Requirement: a level on a shared set-up gives the results of a run of that level alone, bit for bit
/// (the same K, factor and condensation; only their reuse differs).
#[test]
fn a_shared_set_up_gives_the_results_of_a_fresh_run() {
    let s = scene("verification/cases/mms_stop.toml");
    let study = run_study(&s, &levels("2:8,2:32"), None, None, |_| ()).unwrap();
    let mut alone = s.clone();
    alone.set_refine(2).unwrap();
    alone.set_steps(32).unwrap();
    let p = Problem::new(alone).unwrap();
    assert!(p.reused.is_none());
    let (mut max_energy, mut u_last) = (0.0f64, vec![]);
    let mut iterations = 0;
    p.run(tresca_cr::RunOptions::all(), |r: &tresca_cr::StepResult| {
        iterations += r.iterations;
        max_energy = max_energy.max(r.errors.unwrap().energy);
        u_last = r.u.clone();
        Ok(())
    })
    .unwrap();
    let shared: &LevelResult = &study.levels[1];
    assert!(!shared.factorised);
    assert_eq!(shared.max_err.unwrap().energy.to_bits(), max_energy.to_bits());
    assert_eq!(shared.iterations, iterations);
}

/// Requirement: the system shall factorise each pilot mesh of a plan once: the time pilot's levels (one
/// mesh, several grids) and the space pilot's level on that mesh share its set-up, so the plan makes no
/// more set-ups than it has pilot meshes, and fewer than it runs levels; and it shall estimate K's
/// condition number on the first of them only (the time pilot's mesh, where the guard refuses a scene).
#[test]
fn a_plan_factorises_each_pilot_mesh_once() {
    let s = scene("verification/cases/mms_stop.toml");
    let options =
        Options { target: 0.03, quantity: Quantity::Energy, budget: 600.0, pilot_budget: 60.0, max_memory: None };
    let cache = tresca_cr::study::SetupCache::default();
    let p = plan_with_cache(&s, &options, &cache).unwrap();
    let made = cache.factorised();
    let mut meshes = made.clone();
    meshes.sort_unstable();
    meshes.dedup();
    assert_eq!(made.len(), meshes.len(), "a pilot mesh was set up twice: {made:?}");
    assert!(p.time.levels.iter().skip(1).all(|l| !l.factorised), "the time pilot shares its mesh");
    assert!(cache.problems() > made.len() + 2, "{} levels on {} set-ups", cache.problems(), made.len());
    // issue 32 (the planner's own CPU): the condition estimate on the first mesh only, the time pilot's
    assert_eq!(cache.guarded(), [p.time.levels[0].refine], "set-ups {made:?}");
    assert!(made.len() > 1);
}

/// Requirement: the system shall solve each pilot level of a plan once: a level (mesh, steps, common
/// time nodes) an earlier pilot ran is taken from that run. On mms_stop (N = 4) the time pilot's doubling
/// grids 4, 8, 16, 32 are not in the asymptotic range, so its ×4 grids 4, 16, 64, 256 follow: 4 and 16
/// were run by the doubling grids and are not solved again; no level is solved twice in the whole plan.
#[test]
fn a_plan_solves_each_pilot_level_once() {
    let s = scene("verification/cases/mms_stop.toml");
    let options =
        Options { target: 5.6e-3, quantity: Quantity::Energy, budget: 600.0, pilot_budget: 60.0, max_memory: None };
    let cache = tresca_cr::study::SetupCache::default();
    let p = plan_with_cache(&s, &options, &cache).unwrap();
    assert!(p.refused.is_none(), "{:?}", p.refused);
    let solved = cache.solved();
    let mut unique = solved.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(solved.len(), unique.len(), "a pilot level was solved twice: {solved:?}");
    assert_eq!(p.time_ratio, 4);
    let shared: Vec<usize> = p.time.levels.iter().filter(|l| l.shared_run).map(|l| l.steps).collect();
    assert_eq!(shared, [4, 16], "the ×4 grids the doubling grids ran");
}

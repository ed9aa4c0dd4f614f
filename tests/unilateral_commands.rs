//! Results and commands on scenes with normal unknowns (issue 40, "Results" and "Commands"): the normal
//! condition in the VTKHDF/XDMF views, the `[quantities]` `contact_length` and `max_pressure`, and
//! `study`, `plan` and `adapt` on verification/cases/mms_signorini_moving.toml at small refine.

mod common;
use std::path::PathBuf;
use std::process::Output;

use common::{bin, fork_guard, root, spawn, stderr};

const MOVING: &str = "verification/cases/mms_signorini_moving.toml";

fn tmp(name: &str) -> PathBuf {
    common::tmp_in("tresca-unilateral-commands", name)
}

fn cmd(args: &[&str]) -> Output {
    spawn(bin().args(args)).wait_with_output().unwrap()
}

/// mms_signorini_moving with `[quantities]` asking for `extra` (TOML lines), written to `name`.
fn moving_with(name: &str, extra: &str) -> String {
    let text = std::fs::read_to_string(root(MOVING)).unwrap() + "\n[quantities]\n" + extra;
    let p = tmp(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

fn f64_rows(f: &hdf5::File, name: &str) -> Vec<Vec<f64>> {
    let d = f.dataset(name).unwrap();
    let c = d.shape()[1];
    d.read_raw::<f64>().unwrap().chunks(c).map(<[f64]>::to_vec).collect()
}

/// A run of mms_signorini_moving at refine 1: (results file, per step `/tresca/contact/{pressure, gap}`
/// and status, |e| of the Γ_C edges).
type Normal = (PathBuf, [Vec<Vec<f64>>; 3], Vec<f64>);

fn moving_run(name: &str) -> Normal {
    let out = tmp(name);
    let (scene, o) = (root(MOVING), out.display().to_string());
    let mut args = vec!["run", scene.as_str(), "--refine", "1", "-q", "--force", "--threads", "1"];
    args.extend(["-o", o.as_str()]);
    let r = cmd(&args);
    assert!(r.status.success(), "{}", stderr(&r));
    let _g = fork_guard();
    let f = hdf5::File::open(&out).unwrap();
    let status = f.dataset("tresca/contact/status").unwrap();
    let c = status.shape()[1];
    let st = status.read_raw::<u8>().unwrap().chunks(c).map(|r| r.iter().map(|&s| f64::from(s)).collect()).collect();
    let mut sc = common::scene(MOVING);
    sc.set_refine(1).unwrap();
    let len = tresca_cr::Problem::new(sc).unwrap().space.contact.iter().map(|c| c.length).collect();
    (out.clone(), [f64_rows(&f, "tresca/contact/pressure"), f64_rows(&f, "tresca/contact/gap"), st], len)
}

/// The system shall show the pressure, gap and status of every Γ_C edge in the VTKHDF contact block (and
/// the XDMF sidecar) of a run with normal unknowns: at every frame, the `/tresca` values rounded to f32
/// (the views' precision), the status exactly; a bilateral run's contact block has none of them.
#[test]
fn views_hold_the_normal_condition() {
    let (out, [p, g, st], _) = moving_run("views.h5");
    let _g = fork_guard();
    let f = hdf5::File::open(&out).unwrap();
    let c = p[0].len();
    let frames = f.dataset("VTKHDF/contact/Steps/Values").unwrap().read_raw::<f64>().unwrap().len();
    assert_eq!(frames, p.len(), "mms_signorini_moving has 8 steps, all of them frames");
    for (name, want) in [("pressure", &p), ("gap", &g)] {
        let got = f.dataset(&format!("VTKHDF/contact/CellData/{name}")).unwrap().read_raw::<f32>().unwrap();
        let want: Vec<f32> = want.iter().flatten().map(|&v| v as f32).collect();
        assert_eq!(got[..frames * c], want[..], "{name}");
    }
    let got = f.dataset("VTKHDF/contact/CellData/status").unwrap().read_raw::<u8>().unwrap();
    let want: Vec<u8> = st.iter().flatten().map(|&v| v as u8).collect();
    assert_eq!(got[..frames * c], want[..]);
    assert!(want.contains(&2) && want.iter().any(|&s| s < 2), "the scene has separated and touching edges");
    let xdmf = std::fs::read_to_string(out.with_extension("xdmf")).unwrap();
    for name in ["pressure", "gap", "status"] {
        assert_eq!(xdmf.matches(&format!("Attribute Name=\"{name}\"")).count(), frames, "{name} in every frame");
    }
    drop(f);
    drop(_g);
    let bil = tmp("bilateral.h5");
    let o = bil.display().to_string();
    let r = cmd(&["run", &root("verification/cases/paper_example_5_1.toml"), "-q", "--force", "-o", &o]);
    assert!(r.status.success(), "{}", stderr(&r));
    let _g = fork_guard();
    let f = hdf5::File::open(&bil).unwrap();
    let names = f.group("VTKHDF/contact/CellData").unwrap().member_names().unwrap();
    assert_eq!(names, ["sigma_t", "slip", "slip_increment", "stick_slip"]);
}

/// The system shall estimate `contact_length` (Σ|e| over the Γ_C edges not separated at T) and
/// `max_pressure` (max p_e at T) in `study`, each level's value being that of the run at the same
/// refine and steps, exactly.
#[test]
fn study_estimates_contact_length_and_max_pressure() {
    let scene = moving_with("q.toml", "contact_length = true\nmax_pressure = true\n");
    let json = tmp("study.json");
    let j = json.display().to_string();
    let r = cmd(&["study", &scene, "--levels", "0:8,1:8,2:8", "--threads", "1", "--json", &j, "--force"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let out = String::from_utf8_lossy(&r.stdout);
    assert!(out.contains("Output contact_length at T") && out.contains("Output max_pressure at T"), "{out}");
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(s["study"]["output_names"], serde_json::json!(["contact_length", "max_pressure"]));
    let level1 = &s["study"]["levels"][1]["outputs"];
    let (_, [p, _, st], len) = moving_run("study_level1.h5");
    let (p, st) = (p.last().unwrap(), st.last().unwrap());
    let touching: f64 = len.iter().zip(st).filter(|(_, &s)| s < 2.0).map(|(l, _)| l).sum();
    let max_p = p.iter().fold(f64::NEG_INFINITY, |m, &v| m.max(v));
    assert_eq!(level1[0].as_f64().unwrap(), touching);
    assert_eq!(level1[1].as_f64().unwrap(), max_p);
    assert!(touching > 0.0 && touching < len.iter().sum::<f64>() && max_p > 0.0, "contact and separation at T");
}

/// The system shall refuse `contact_length` and `max_pressure` on a scene without normal unknowns, in
/// `[quantities]` and as `plan --quantity`, with a message naming the quantity (exit 1, no panic).
#[test]
fn normal_quantities_refused_without_normal_unknowns() {
    let text = std::fs::read_to_string(root("verification/cases/paper_example_5_1.toml")).unwrap();
    for key in ["contact_length", "max_pressure"] {
        let p = tmp(&format!("bil_{key}.toml"));
        std::fs::write(&p, format!("{text}\n[quantities]\n{key} = true\n")).unwrap();
        let r = cmd(&["study", p.to_str().unwrap(), "--levels", "0:4,1:4"]);
        assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
        assert!(
            stderr(&r).contains(&format!("quantities.{key}")) && stderr(&r).contains("unilateral"),
            "{}",
            stderr(&r)
        );
        let q = key.replace('_', "-");
        let ex = root("verification/cases/paper_example_5_1.toml");
        let r = cmd(&["plan", &ex, "--target", "0.01", "--quantity", &q, "--budget", "60s"]);
        assert_eq!(r.status.code(), Some(1), "{}", stderr(&r));
        assert!(stderr(&r).contains(key) && stderr(&r).contains("Coulomb"), "{}", stderr(&r));
    }
}

/// The system shall plan a unilateral scene for the energy norm and for `max_pressure`: a plan whose
/// refine is within the pilots' range, with the command to run it.
#[test]
fn plan_works_on_a_unilateral_scene() {
    for q in ["energy-norm", "max-pressure"] {
        let r = cmd(&["plan", &root(MOVING), "--target", "0.05", "--quantity", q, "--budget", "60s", "--threads", "1"]);
        assert!(r.status.success(), "{q}: {}", stderr(&r));
        let out = String::from_utf8_lossy(&r.stdout);
        assert!(out.contains("run it: tresca-cr run"), "{q}: {out}");
    }
}

/// The system shall adapt a unilateral scene: each level is a whole run with more triangles, and the
/// true energy error ([exact]) and the estimator decrease from level to level.
#[test]
fn adapt_works_on_a_unilateral_scene() {
    let json = tmp("adapt.json");
    let j = json.display().to_string();
    let r = cmd(&["adapt", &root(MOVING), "--levels", "4", "--threads", "1", "--json", &j, "--force"]);
    assert!(r.status.success(), "{}", stderr(&r));
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let levels = s["adapt"]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4);
    let col = |k: &str| levels.iter().map(|l| l[k].as_f64().unwrap()).collect::<Vec<_>>();
    for k in ["triangles", "estimator", "error"] {
        let v = col(k);
        let grows = k == "triangles";
        assert!(v.windows(2).all(|w| (w[1] > w[0]) == grows), "{k}: {v:?}");
    }
}

//! Results file: round trip of every dataset, refusal of existing files and non-finite values,
//! SIGKILL safety (a child process killed at random moments) and bit-identical `resume`.

mod common;
use common::same_results;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};
use tresca_cr::fem::space::Element;
use tresca_cr::output::{sidecar, Run, Writer};
use tresca_cr::{Problem, Scene, StepResult};

fn tmp(name: &str) -> PathBuf {
    let p = common::tmp_in("tresca-output", name);
    let _ = std::fs::remove_file(&p);
    p
}

fn example(refine: u32, steps: usize) -> Scene {
    let mut s = common::scene("verification/cases/paper_example_5_1.toml");
    s.set_refine(refine).unwrap();
    s.set_steps(steps).unwrap();
    s
}

/// Run `p`, writing every step; returns the results.
fn run_written(p: &Problem, path: &Path) -> Vec<StepResult> {
    let mut w = Writer::create(path, &Run::of(p), true).unwrap();
    let mut out = Vec::new();
    p.run(tresca_cr::RunOptions::all(), |r| {
        out.push(r.clone());
        w.write_step(r)
    })
    .unwrap();
    w.finish("completed").unwrap();
    out
}

fn f64s(f: &hdf5::File, name: &str) -> Vec<f64> {
    f.dataset(name).unwrap_or_else(|e| panic!("{name}: {e}")).read_raw::<f64>().unwrap()
}
fn f32s(f: &hdf5::File, name: &str) -> Vec<f32> {
    f.dataset(name).unwrap_or_else(|e| panic!("{name}: {e}")).read_raw::<f32>().unwrap()
}
fn shape(f: &hdf5::File, name: &str) -> Vec<usize> {
    f.dataset(name).unwrap_or_else(|e| panic!("{name}: {e}")).shape()
}
fn attr_str(f: &hdf5::File, group: &str, name: &str) -> String {
    f.group(group)
        .unwrap()
        .attr(name)
        .unwrap()
        .read_scalar::<hdf5::types::VarLenUnicode>()
        .unwrap()
        .as_str()
        .to_string()
}
fn attr_i64(f: &hdf5::File, group: &str, name: &str) -> i64 {
    f.group(group).unwrap().attr(name).unwrap().read_scalar::<i64>().unwrap()
}

/// f32 agreement relative to the array's scale.
fn close32(a: &[f32], b: &[f64], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: length");
    let scale = b.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(((*x as f64) - y).abs() <= 1e-6 * scale, "{what}[{k}]: {x} vs {y}");
    }
}

/// Every dataset of the file against the in-memory results, with the VTK fields recomputed here by
/// evaluating the CR basis at the triangle vertices (an independent route from the writer's formula).
fn check_file(p: &Problem, rs: &[StepResult], path: &Path) {
    let f = hdf5::File::open(path).unwrap();
    let (mesh, sp) = (&p.mesh, &p.space);
    let (nt, ne, nc) = (mesh.tris.len(), mesh.edges.len(), sp.contact.len());
    let n1 = rs.len();
    assert_eq!(attr_i64(&f, "tresca/steps", "completed"), n1 as i64);
    assert_eq!(attr_i64(&f, "VTKHDF/body/Steps", "NSteps"), n1 as i64);
    if nc > 0 {
        assert_eq!(attr_i64(&f, "VTKHDF/contact/Steps", "NSteps"), n1 as i64);
    }
    assert_eq!(attr_str(&f, "tresca", "scene"), p.scene.text);
    assert_eq!(attr_str(&f, "tresca", "status"), "completed");
    assert_eq!(attr_str(&f, "tresca", "version"), env!("CARGO_PKG_VERSION"));
    assert_eq!(attr_str(&f, "tresca", "solver"), p.scene.solver.method.name());
    assert_eq!(f64s(&f, "tresca/mesh/points"), mesh.points.as_flattened());
    let tris: Vec<i64> = f.dataset("tresca/mesh/triangles").unwrap().read_raw().unwrap();
    assert_eq!(tris, mesh.tris.iter().flatten().map(|&v| v as i64).collect::<Vec<_>>());
    assert_eq!(shape(&f, "tresca/mesh/edges"), [ne, 2]);
    assert_eq!(shape(&f, "tresca/u"), [n1, ne, 2]);
    let times: Vec<f64> = rs.iter().map(|r| r.t).collect();
    assert_eq!(f64s(&f, "tresca/times"), times);
    assert_eq!(f64s(&f, "VTKHDF/body/Steps/Values"), times);
    let u = f64s(&f, "tresca/u");
    let energy = f64s(&f, "tresca/energy");
    let iters: Vec<i64> = f.dataset("tresca/steps/iterations").unwrap().read_raw().unwrap();
    let res = f64s(&f, "tresca/steps/residual");
    for (n, r) in rs.iter().enumerate() {
        let mid = sp.midpoint_values(&r.u);
        assert_eq!(&u[n * 2 * ne..(n + 1) * 2 * ne], mid.as_flattened(), "tresca/u step {n}");
        assert_eq!(energy[n], r.energy);
        assert_eq!(iters[n], r.iterations as i64);
        assert_eq!(res[n], r.residual);
    }
    if nc > 0 {
        let slip = f64s(&f, "tresca/contact/slip");
        let sig = f64s(&f, "tresca/contact/sigma_t");
        let mu = f64s(&f, "tresca/contact/mu");
        let state: Vec<u8> = f.dataset("tresca/contact/state").unwrap().read_raw().unwrap();
        let g = f64s(&f, "tresca/contact/g");
        for (k, c) in sp.contact.iter().enumerate() {
            assert_eq!(g[k], c.g_mean);
        }
        for (n, r) in rs.iter().enumerate() {
            assert_eq!(&slip[n * nc..(n + 1) * nc], &r.slip[..]);
            assert_eq!(&mu[n * nc..(n + 1) * nc], &r.mu[..]);
            assert!(state[n * nc..(n + 1) * nc].iter().zip(&r.state).all(|(a, b)| *a == *b as u8));
            for k in 0..nc {
                assert_eq!(sig[n * nc + k], -r.mu[k] / sp.contact[k].length);
            }
        }
    }
    if p.errors.is_some() {
        let e = f64s(&f, "tresca/errors/energy");
        let l2 = f64s(&f, "tresca/errors/l2");
        for (n, r) in rs.iter().enumerate() {
            assert_eq!(e[n], r.errors.unwrap().energy);
            assert_eq!(l2[n], r.errors.unwrap().l2);
        }
    }
    // VTKHDF: a collection of the body (triangles) and the contact line (Γ_C edges), each with its own fields
    let np = 3 * nt;
    let ncell = nt;
    assert_eq!(shape(&f, "VTKHDF/body/Points"), [np, 3]);
    assert_eq!(shape(&f, "VTKHDF/body/Types"), [nt]);
    assert_eq!(shape(&f, "VTKHDF/body/PointData/displacement"), [n1 * np, 3]);
    assert_eq!(shape(&f, "VTKHDF/body/CellData/stress"), [n1 * nt, 6]);
    assert!(f.dataset("VTKHDF/body/CellData/slip").is_err(), "the body carries no contact field");
    let disp = f32s(&f, "VTKHDF/body/PointData/displacement");
    let vm = f32s(&f, "VTKHDF/body/CellData/von_mises");
    let stress = f32s(&f, "VTKHDF/body/CellData/stress");
    let (lam, mu) = (p.law.lam, p.law.mu);
    for (n, r) in rs.iter().enumerate() {
        let mid = sp.midpoint_values(&r.u);
        let mut want = Vec::new();
        let mut want_vm = Vec::new();
        let mut want_sxx = Vec::new();
        for t in 0..nt {
            let el = Element::new(mesh, t);
            for j in 0..3 {
                let phi = Element::phi(el.bary(el.pts[j]));
                let mut v = [0.0; 3];
                for i in 0..3 {
                    let ue = mid[mesh.tri_edges[t][i]];
                    v[0] += phi[i] * ue[0];
                    v[1] += phi[i] * ue[1];
                }
                want.extend(v);
            }
            // stress from a finite difference of the P1 vertex values (exact for a linear field)
            let vals: Vec<[f64; 2]> =
                (0..3).map(|j| [want[want.len() - 9 + 3 * j], want[want.len() - 8 + 3 * j]]).collect();
            let mut gu = [[0.0; 2]; 2];
            for (v, g) in vals.iter().zip(&el.grad_lambda) {
                for (row, va) in gu.iter_mut().zip(v) {
                    for (gab, gb) in row.iter_mut().zip(g) {
                        *gab += va * gb;
                    }
                }
            }
            let tr = gu[0][0] + gu[1][1];
            let (sxx, syy, szz, sxy) =
                (lam * tr + 2.0 * mu * gu[0][0], lam * tr + 2.0 * mu * gu[1][1], lam * tr, mu * (gu[0][1] + gu[1][0]));
            want_sxx.push(sxx);
            want_vm.push(
                (0.5 * ((sxx - syy).powi(2) + (syy - szz).powi(2) + (szz - sxx).powi(2)) + 3.0 * sxy * sxy).sqrt(),
            );
        }
        close32(&disp[n * 3 * np..(n + 1) * 3 * np], &want, &format!("displacement step {n}"));
        close32(&vm[n * ncell..n * ncell + nt], &want_vm, &format!("von_mises step {n}"));
        let sxx: Vec<f32> = (0..nt).map(|t| stress[(n * ncell + t) * 6]).collect();
        close32(&sxx, &want_sxx, &format!("stress xx step {n}"));
    }
    if nc > 0 {
        assert_eq!(shape(&f, "VTKHDF/contact/Points"), [2 * nc, 3]);
        assert_eq!(shape(&f, "VTKHDF/contact/Types"), [nc]);
        assert!(f.dataset("VTKHDF/contact/CellData/von_mises").is_err(), "the contact line carries no body field");
        assert_eq!(f64s(&f, "VTKHDF/contact/Steps/Values"), times);
        let st = f32s(&f, "VTKHDF/contact/CellData/sigma_t");
        let inc = f32s(&f, "VTKHDF/contact/CellData/slip_increment");
        let n = n1 - 1;
        let want: Vec<f64> = (0..nc).map(|k| -rs[n].mu[k] / sp.contact[k].length).collect();
        close32(&st[n * nc..(n + 1) * nc], &want, "sigma_t");
        let want: Vec<f64> = (0..nc).map(|k| rs[n].slip[k] - rs[n - 1].slip[k]).collect();
        close32(&inc[n * nc..(n + 1) * nc], &want, "slip_increment");
        // the contact line's points move with the body: its displacement is the body's at the same points
        let (cp, cd) = (f64s(&f, "VTKHDF/contact/Points"), f32s(&f, "VTKHDF/contact/PointData/displacement"));
        let bp = f64s(&f, "VTKHDF/body/Points");
        for q in 0..2 * nc {
            let b = (0..np).find(|&b| bp[3 * b..3 * b + 3] == cp[3 * q..3 * q + 3]).expect("contact point on the body");
            let on_body = (0..np).filter(|&b| bp[3 * b..3 * b + 3] == cp[3 * q..3 * q + 3]).any(|b| {
                disp[n * 3 * np + 3 * b..n * 3 * np + 3 * b + 3] == cd[n * 6 * nc + 3 * q..n * 6 * nc + 3 * q + 3]
            });
            assert!(on_body, "contact point {q} (body point {b}): displacement is none of the body's there");
        }
    }
    // XDMF virtual datasets resolve to the same rows
    for k in 0..n1 {
        let v = f32s(&f, &format!("xdmf/body/displacement/{k:06}"));
        assert_eq!(v, &disp[k * 3 * np..(k + 1) * 3 * np]);
        let v = f32s(&f, &format!("xdmf/body/stress/{k:06}"));
        assert_eq!(v, &stress[k * 6 * ncell..(k + 1) * 6 * ncell]);
    }
    let x = std::fs::read_to_string(sidecar(path)).unwrap();
    let collections = if nc > 0 { 2 } else { 1 };
    assert_eq!(x.matches("<Grid Name=\"step_").count(), collections * n1);
    assert!(x.trim_end().ends_with("</Xdmf>"));
}

#[test]
fn round_trip_example_with_contact() {
    let p = Problem::new(example(1, 12)).unwrap();
    let path = tmp("example.h5");
    let rs = run_written(&p, &path);
    check_file(&p, &rs, &path);
}

#[test]
fn round_trip_with_exact_solution_errors() {
    let p = Problem::new(common::scene("verification/cases/mms_stick_to_slip.toml")).unwrap();
    let path = tmp("mms.h5");
    let rs = run_written(&p, &path);
    assert!(rs[1].errors.is_some());
    check_file(&p, &rs, &path);
}

#[test]
fn round_trip_without_contact() {
    let p = Problem::new(common::scene("verification/cases/mms_elastic.toml")).unwrap();
    assert!(p.space.contact.is_empty());
    let path = tmp("elastic.h5");
    let rs = run_written(&p, &path);
    check_file(&p, &rs, &path);
    let f = hdf5::File::open(&path).unwrap();
    assert!(f.group("tresca/contact").is_err());
}

#[test]
fn existing_file_is_refused_without_force() {
    let p = Problem::new(example(0, 2)).unwrap();
    let path = tmp("exists.h5");
    std::fs::write(&path, b"keep me").unwrap();
    let err = Writer::create(&path, &Run::of(&p), false).err().expect("must refuse").to_string();
    assert!(err.contains(&path.display().to_string()) && err.contains("--force") && err.contains("--resume"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"keep me");
    Writer::create(&path, &Run::of(&p), true).unwrap();
}

#[test]
fn non_finite_values_are_refused_and_earlier_steps_survive() {
    let p = Problem::new(example(0, 4)).unwrap();
    let path = tmp("nan.h5");
    let mut w = Writer::create(&path, &Run::of(&p), true).unwrap();
    let r0 = p.initial().unwrap();
    w.write_step(&r0).unwrap();
    let mut bad = p.step(1, &r0, &mut Vec::new(), true).unwrap();
    bad.u[3] = f64::NAN;
    let err = w.write_step(&bad).unwrap_err().to_string();
    assert!(err.contains("u[3]") && err.contains("not finite"), "{err}");
    bad.u[3] = 0.0;
    bad.mu[0] = f64::INFINITY;
    assert!(w.write_step(&bad).is_err());
    drop(w);
    let f = hdf5::File::open(&path).unwrap();
    assert_eq!(attr_i64(&f, "tresca/steps", "completed"), 1);
    assert_eq!(shape(&f, "tresca/u")[0], 1);
    assert!(f64s(&f, "tresca/u").iter().all(|v| v.is_finite()));
}

/// A new file is moved under its name only at its first commit: a run that fails at step 0 (or is
/// killed before it) leaves an old results file and its sidecar byte for byte as they were, and
/// neither a file without a step nor `.partial` leftovers.
#[test]
fn a_run_that_commits_nothing_replaces_nothing() {
    let p = Problem::new(example(0, 4)).unwrap();
    let path = tmp("keep.h5");
    run_written(&p, &path);
    let xdmf = tresca_cr::output::sidecar(&path);
    let (h5_before, xdmf_before) = (std::fs::read(&path).unwrap(), std::fs::read(&xdmf).unwrap());
    let mut w = Writer::create(&path, &Run::of(&p), true).unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), h5_before, "created, nothing committed: old file in place");
    let mut bad = p.initial().unwrap();
    bad.u[0] = f64::NAN;
    assert!(w.write_step(&bad).is_err());
    w.finish("stopped: step 0").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), h5_before);
    assert_eq!(std::fs::read(&xdmf).unwrap(), xdmf_before);
    let dir: Vec<_> = std::fs::read_dir(path.parent().unwrap())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("keep.") && n.ends_with(".partial"))
        .collect();
    assert!(dir.is_empty(), "leftovers {dir:?}");
}

#[test]
fn resume_after_drop_is_bit_identical() {
    let p = Problem::new(example(1, 24)).unwrap();
    let full = tmp("full.h5");
    run_written(&p, &full);
    let part = tmp("part.h5");
    {
        let mut w = Writer::create(&part, &Run::of(&p), false).unwrap();
        let mut k = 0;
        let r = p.run(tresca_cr::RunOptions::all(), |r| {
            k += 1;
            if k > 9 {
                return Err(tresca_cr::Error::Linear("stop".into()));
            }
            w.write_step(r)
        });
        assert!(r.is_err());
        // dropped without finish: as after a crash between steps
    }
    let err = Writer::create(&part, &Run::of(&p), false).err().unwrap().to_string();
    assert!(err.contains("--resume"));
    let (mut w, last) = Writer::resume(&part, &Run::of(&p)).unwrap();
    let last = last.expect("a committed step");
    assert_eq!((last.n, w.completed()), (8, 9));
    p.run(tresca_cr::RunOptions::after(last), |r| w.write_step(r)).unwrap();
    w.finish("completed").unwrap();
    same_results(&full, &part);
}

#[test]
fn resume_refuses_a_different_run() {
    let p = Problem::new(example(0, 6)).unwrap();
    let path = tmp("other.h5");
    run_written(&p, &path);
    let q = Problem::new(example(0, 8)).unwrap();
    let err = Writer::resume(&path, &Run::of(&q)).err().unwrap().to_string();
    assert!(err.contains("time steps"), "{err}");
    let q = Problem::new(example(1, 6)).unwrap();
    let err = Writer::resume(&path, &Run::of(&q)).err().unwrap().to_string();
    assert!(err.contains("mesh"), "{err}");
    let mut s = example(0, 6);
    s.text.push_str("\n# changed\n");
    let err = Writer::resume(&path, &Run::of(&Problem::new(s).unwrap())).err().unwrap().to_string();
    assert!(err.contains("scene"), "{err}");
}

/// Child side of the SIGKILL test: write a long run slowly to the file named by TRESCA_KILL_CHILD.
#[test]
fn kill_child_writer() {
    let Ok(path) = std::env::var("TRESCA_KILL_CHILD") else { return };
    let p = Problem::new(example(1, 400)).unwrap();
    let mut w = Writer::create(Path::new(&path), &Run::of(&p), true).unwrap();
    p.run(tresca_cr::RunOptions::all(), |r| {
        std::thread::sleep(Duration::from_micros(300));
        w.write_step(r)
    })
    .unwrap();
    w.finish("completed").unwrap();
}

#[test]
fn sigkill_at_random_moments_leaves_complete_steps_and_resume_is_bit_identical() {
    let p = Problem::new(example(1, 400)).unwrap();
    let full = tmp("kill_full.h5");
    run_written(&p, &full);
    let exe = std::env::current_exe().unwrap();
    let child = |path: &Path| {
        std::process::Command::new(&exe)
            .args(["--exact", "kill_child_writer", "--test-threads=1", "--nocapture"])
            .env("TRESCA_KILL_CHILD", path)
            .stdout(std::process::Stdio::null())
            .spawn()
            .unwrap()
    };
    // kill at fractions of the time an uninterrupted child takes, so the kills land mid-run however
    // fast the machine and the writer are
    let start = Instant::now();
    assert!(child(&tmp("kill_timing.h5")).wait().unwrap().success());
    let whole = start.elapsed();
    let mut resumed = 0;
    for (i, frac) in [0.2, 0.35, 0.5, 0.65, 0.8, 0.95].into_iter().enumerate() {
        let path = tmp(&format!("kill_{i}.h5"));
        let mut child = child(&path);
        std::thread::sleep(whole.mul_f64(frac));
        child.kill().unwrap(); // SIGKILL
        child.wait().unwrap();
        if !path.exists() {
            continue; // killed before the file was moved into place
        }
        let f = hdf5::File::open(&path).unwrap_or_else(|e| panic!("kill {i}: the file must open: {e}"));
        let done = attr_i64(&f, "tresca/steps", "completed") as usize;
        let every = attr_i64(&f, "tresca", "frame_every") as usize;
        let last = p.n_steps();
        let frames = done.div_ceil(every) + usize::from(done > last && !last.is_multiple_of(every));
        assert_eq!(attr_i64(&f, "VTKHDF/body/Steps", "NSteps") as usize, frames);
        assert!(shape(&f, "tresca/u")[0] >= done);
        // every completed step equals the uninterrupted run
        let g = hdf5::File::open(&full).unwrap();
        let ne = p.mesh.edges.len();
        let (a, b) = (f64s(&f, "tresca/u"), f64s(&g, "tresca/u"));
        assert_eq!(&a[..done * 2 * ne], &b[..done * 2 * ne], "kill {i}: completed steps differ");
        drop(f);
        if done == 0 {
            continue;
        }
        let (mut w, last) = Writer::resume(&path, &Run::of(&p)).unwrap();
        let last = last.expect("a committed step");
        assert_eq!(last.n + 1, done);
        p.run(tresca_cr::RunOptions::after(last), |r| w.write_step(r)).unwrap();
        w.finish("completed").unwrap();
        same_results(&full, &path);
        resumed += 1;
    }
    assert!(resumed >= 3, "only {resumed} kills landed mid-run");
}

/// `cargo test --release --test output -- --ignored --nocapture timing`: the paper's finest run, with
/// the default options, strict per-step commits, only 2 frames, and every step a frame.
#[test]
#[ignore]
fn timing_example_5_1_finest() {
    use tresca_cr::output::Options;
    let (refine, steps) = (4u32, 640usize);
    let t0 = Instant::now();
    let p = Problem::new(example(refine, steps)).unwrap();
    let setup = t0.elapsed().as_secs_f64();
    let t4 = Instant::now();
    p.run(tresca_cr::RunOptions::all(), |_| Ok(())).unwrap();
    println!(
        "refine {refine} steps {steps}: unknowns {}, set-up {setup:.3}s, solve without writer {:.3}s",
        p.space.n_dofs,
        t4.elapsed().as_secs_f64()
    );
    for (what, opts) in [
        ("default (<= 51 frames, commit every 0.05 s)", Options { force: true, ..Options::default() }),
        ("commit every step", Options { force: true, commit_interval: 0.0, ..Options::default() }),
        ("2 frames", Options { force: true, frame_every: Some(steps), ..Options::default() }),
        ("every step a frame", Options { force: true, frame_every: Some(1), ..Options::default() }),
    ] {
        let path = tmp("timing.h5");
        let t1 = Instant::now();
        let mut w = Writer::create_with(&path, &Run::of(&p), &opts).unwrap();
        let create = t1.elapsed().as_secs_f64();
        let t2 = Instant::now();
        p.run(tresca_cr::RunOptions::all(), |r| w.write_step(r)).unwrap();
        let sec = w.seconds;
        w.finish("completed").unwrap();
        println!(
            "  {what}: create {create:.3}s, run+write+finish {:.3}s (write_step {:.3}s, H5Fflush {:.3}s), file {:.1} MB",
            t2.elapsed().as_secs_f64(),
            sec[0],
            sec[1],
            std::fs::metadata(&path).unwrap().len() as f64 / 1e6
        );
    }
}

#[test]
#[ignore]
fn bench_dataset_creation() {
    let path = tmp("bench.h5");
    let f = hdf5::File::create(&path).unwrap();
    let g = f.create_group("x").unwrap();
    let data = vec![0f32; 6144 * 3];
    let t = Instant::now();
    for k in 0..5000 {
        let v = ndarray::ArrayView2::from_shape((6144, 3), &data).unwrap();
        g.new_dataset_builder().with_data(&v).create(format!("{k}").as_str()).unwrap();
        if k % 8 == 0 {
            f.flush().unwrap();
        }
    }
    println!("5000 plain datasets with data: {:.3}s", t.elapsed().as_secs_f64());
    let g = f.create_group("y").unwrap();
    let t = Instant::now();
    for k in 0..5000 {
        g.new_dataset::<f32>().shape((6144, 3)).create(format!("{k}").as_str()).unwrap();
        if k % 8 == 0 {
            f.flush().unwrap();
        }
    }
    println!("5000 plain datasets without data: {:.3}s", t.elapsed().as_secs_f64());
}

/// Writes `$TRESCA_SAMPLE_OUT` (Example 5.1, refine 2, 160 steps) for the Python checks and pictures.
#[test]
#[ignore]
fn write_sample_file() {
    let Ok(out) = std::env::var("TRESCA_SAMPLE_OUT") else { return };
    let p = Problem::new(example(2, 160)).unwrap();
    run_written(&p, Path::new(&out));
}

//! Threads the system refuses: a process at its limit of address space for thread stacks (as a limit of
//! threads, `ulimit -u` or a cgroup's `pids.max`, would refuse them; root, which runs these tests, is not
//! held by `ulimit -u`). Each refused thread is a typed error naming it, or its work is done on the
//! thread that asked, never a panic or a half-written results file.

use super::{address_space, base, no_leftovers, s, tmp};
use crate::common::{bin, spawn, stderr};
use std::collections::BTreeSet;
use std::process::Output;

/// Each thread's stack (`RUST_MIN_STACK`, read by std and so by rayon's pool): far above what the run
/// needs besides, so the limit below decides how many threads can be alive at once, and below the RAM
/// so the kernel's overcommit heuristic does not refuse every stack.
const STACK: u64 = 4 << 30;

/// `run` of `args` with `RUST_MIN_STACK` = [`STACK`] and an address space of `limit` bytes.
fn run_limited(args: &[&str], limit: u64) -> Output {
    let mut c = bin();
    c.args(args).env("RUST_MIN_STACK", STACK.to_string());
    spawn(address_space(&mut c, limit)).wait_with_output().unwrap()
}

/// The system shall end a run whose threads the system refuses with exit code 1 and a message naming the
/// thread and the limits that refuse it (or finish it, where the work can be done on the thread that
/// asked), never with a panic, and shall leave no results file, lock or partial file behind. Address
/// spaces from 1 to 24 GB in steps of 1 GB with 4 GB stacks hold from no thread to all of a small run's,
/// so the refusal reaches each thread the run starts, in turn.
#[test]
fn refused_threads_are_errors_not_panics() {
    let scene = base();
    let mut refused = BTreeSet::new();
    let (mut finished, mut kernel_aborts) = (0, 0);
    for gb in 1..=24u64 {
        let out = tmp(&format!("threads_{gb}.h5"));
        let _ = std::fs::remove_file(&out);
        let o = run_limited(&["run", &scene, "-q", "-o", s(&out), "--threads", "2"], gb << 30);
        let e = stderr(&o);
        assert!(!e.contains("panicked"), "{gb} GB: {e}");
        match o.status.code() {
            Some(0) => finished += 1,
            Some(1) => {
                let what = e.split("cannot start a thread for ").nth(1).and_then(|r| r.split(':').next());
                let Some(what) = what else { panic!("{gb} GB: no thread named: {e}") };
                assert!(e.contains("pids.max") && e.contains("RUST_MIN_STACK"), "{gb} GB: {e}");
                refused.insert(what.to_string());
                assert!(!out.exists(), "{gb} GB: a results file was left");
                assert!(!out.with_extension("xdmf").exists(), "{gb} GB: a sidecar was left");
            }
            // Known limit, not this crate's error path (left open): private-gemm-x86 reserves its packing
            // buffer (`kernel_reserve`, twice the reported L3) on a thread's first product and aborts when
            // the address space cannot hold it. `address_space` leaves room for it on four threads, but a
            // limit that admits one more 4 GB stack can leave less than a buffer; only that exact
            // allocation is let through, counted apart.
            None if e.contains(&format!("memory allocation of {} bytes failed", super::kernel_reserve())) => {
                kernel_aborts += 1;
                continue;
            }
            c => panic!("{gb} GB: exit {c:?}: {e}"),
        }
        no_leftovers(&out);
    }
    // the pool's threads are the first refused; a later thread must be reached too (the first spawns that
    // panicked were the set-up's), and a limit that holds every thread must let the run finish
    assert!(refused.contains("rayon's pool of worker threads"), "{refused:?}");
    assert!(refused.len() >= 2, "no thread after the pool was refused: {refused:?}");
    assert!(finished > 0, "no address space of the sweep let the run finish: {refused:?}");
    // a buffer under 1 GB fits below each added 4 GB stack but in at most one 1 GB step of it: at most one
    // limit per thread count the sweep passes (measured: 1 of 24 with a 960 MiB buffer)
    assert!(kernel_aborts <= 3, "{kernel_aborts} of 24 limits ended in the kernel's buffer: {refused:?}");
}

//! The integration tests that call the library in-process and start no process, gathered into one test
//! binary (`cargo test --release --locked --test library [MODULE::][NAME]`): one link instead of one per
//! file. Tests that start the release binary stay in binaries of their own (tests/*.rs): a child forked
//! while another test holds an HDF5 file open would inherit its lock (`fork_guard` in tests/common/mod.rs).
//!
//! A new file here must be declared below; `every_file_is_declared` fails otherwise.

#[path = "../common/mod.rs"]
mod common;

mod adapt_bisect;
mod adapt_estimate;
mod adapt_time;
mod blocks;
mod boundary_data;
mod contact;
mod elasticity;
mod energy_audit;
mod error_norms;
mod factor_once;
mod floating;
mod free_response;
mod separated_loads;
mod stability;
mod unilateral;
mod validation;

/// The system shall run every test file of tests/library/: each one is declared as a module of this binary
/// (an undeclared file would compile into nothing and its tests would silently not run).
#[test]
fn every_file_is_declared() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/library");
    let main = std::fs::read_to_string(dir.join("main.rs")).unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        let Some(module) = name.strip_suffix(".rs").filter(|m| *m != "main") else { continue };
        assert!(main.lines().any(|l| l == format!("mod {module};")), "tests/library/{name} is not declared in main.rs");
    }
}

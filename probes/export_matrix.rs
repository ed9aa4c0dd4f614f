//! The factorisation bench's matrix and tresca-cr's side of it (`verification/bench/factorisation.py`).
//!
//! `export_matrix SCENE REFINE DIR` writes the reduced stiffness K of SCENE at REFINE (the unknowns of
//! V_h, u·n = 0 on Γ_C eliminated; what every run factorises) into DIR as three `.npy` files, its lower
//! triangle in CSC form: `indptr.npy` (int64), `indices.npy` (int64), `data.npy` (float64), with n and the
//! entries in `info.json`.
//!
//! `export_matrix SCENE REFINE --time` sets the mesh up as a run does (mesh and space, assembly with the
//! ordering and symbolic factorisation beside it, numeric factorisation; `stepping::MeshSetUp`) and
//! prints one JSON line: the phases' wall times, nnz_k (the entries of K's lower triangle, what a run
//! keeps), nnz(L), the factorisation's flops Σ_j c_j² and the
//! process's CPU time.
use std::io::Write;
use tresca_cr::stepping::MeshSetUp;
use tresca_cr::Scene;

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() != 3 {
        eprintln!("usage: export_matrix SCENE REFINE (DIR | --time)");
        std::process::exit(2);
    }
    let mut scene = Scene::from_file(std::path::Path::new(&a[0])).unwrap_or_else(|e| fail(&e.to_string()));
    scene
        .set_refine(a[1].parse().unwrap_or_else(|_| fail("REFINE: a number")))
        .unwrap_or_else(|e| fail(&e.to_string()));
    let m = MeshSetUp::new(&scene, tresca_cr::stepping::Guard::Estimate).unwrap_or_else(|e| fail(&e.to_string()));
    if a[2] == "--time" {
        let t = m.times();
        let (flops, entries) = m.factor().flops_and_entries();
        println!(
            "{{\"unknowns\": {}, \"nnz_k\": {}, \"space\": {}, \"assembly\": {}, \"factorisation\": {}, \"nnz_l\": {}, \
             \"nnz_l_stored\": {}, \"flops\": {}, \"cpu\": {}}}",
            m.unknowns(),
            m.stiffness().compute_nnz(),
            t.space,
            t.assembly,
            t.factorisation,
            entries,
            m.factor().len_val(),
            flops,
            cpu_seconds()
        );
        return;
    }
    export(&m, std::path::Path::new(&a[2])).unwrap_or_else(|e| fail(&format!("{}: {e}", a[2])));
}

fn fail(msg: &str) -> ! {
    eprintln!("error: {msg}");
    std::process::exit(1)
}

/// The lower triangle of K as CSC `.npy` files in `dir`.
fn export(m: &MeshSetUp, dir: &std::path::Path) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let k = m.stiffness();
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let (mut ptr, mut idx, mut data) = (vec![0i64], Vec::new(), Vec::new());
    for j in 0..k.ncols() {
        for p in cp[j]..cp[j + 1] {
            if ri[p] >= j {
                idx.push(ri[p] as i64);
                data.push(val[p]);
            }
        }
        ptr.push(idx.len() as i64);
    }
    npy(&dir.join("indptr.npy"), "<i8", ptr.iter().flat_map(|v| v.to_le_bytes()), ptr.len())?;
    npy(&dir.join("indices.npy"), "<i8", idx.iter().flat_map(|v| v.to_le_bytes()), idx.len())?;
    npy(&dir.join("data.npy"), "<f8", data.iter().flat_map(|v| v.to_le_bytes()), data.len())?;
    let info = format!("{{\"n\": {}, \"nnz_lower\": {}, \"unknowns\": {}}}\n", k.nrows(), idx.len(), m.unknowns());
    std::fs::write(dir.join("info.json"), info)
}

/// A one-dimensional `.npy` file (format 1.0) of `len` values of `dtype`.
fn npy(path: &std::path::Path, dtype: &str, bytes: impl Iterator<Item = u8>, len: usize) -> std::io::Result<()> {
    let mut header = format!("{{'descr': '{dtype}', 'fortran_order': False, 'shape': ({len},), }}");
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(b"\x93NUMPY\x01\x00")?;
    f.write_all(&(header.len() as u16).to_le_bytes())?;
    f.write_all(header.as_bytes())?;
    f.write_all(&bytes.collect::<Vec<u8>>())?;
    f.flush()
}

/// CPU seconds of the process so far (user + system, all threads).
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage fills the struct given.
    let ru = unsafe {
        let mut ru: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut ru);
        ru
    };
    let t = |tv: libc::timeval| tv.tv_sec as f64 + tv.tv_usec as f64 * 1e-6;
    t(ru.ru_utime) + t(ru.ru_stime)
}

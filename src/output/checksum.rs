//! The per-step checksums of `tresca/steps/checksum` (the layout: `output::tresca`'s module doc): XXH64
//! (seed 0) of each step's rows of every series it covers, in order, as little-endian bytes; the
//! attribute [`COVERS`] names those series. `tresca_py.checksum` computes the same.

use super::h5::Series;
use super::rows::Rows;

/// The attribute of `steps/checksum` naming the series it covers, in their order ("times, u, …"; the
/// audit's last). Files written before the checksums covered the audit have no such attribute.
pub const COVERS: &str = "series";

/// The XXH64 of each of `k` steps whose rows are the k equal consecutive parts of every slice of
/// `series` (the bytes of consecutive steps of each series, in the order of the module doc).
pub fn step_checksums(series: &[&[u8]], k: usize) -> Vec<u64> {
    (0..k)
        .map(|i| {
            let mut h = xxhash_rust::xxh64::Xxh64::new(0);
            for s in series {
                let row = s.len() / k;
                h.update(&s[i * row..(i + 1) * row]);
            }
            h.digest()
        })
        .collect()
}

/// The audit's series under `steps`, in `stepping::Audit::as_array`'s order.
pub const AUDIT: [&str; 6] = [
    "external_work",
    "boundary_work",
    "stored_energy",
    "friction_dissipation",
    "euler_dissipation",
    "balance_residual",
];

/// The series a new file's checksums cover, in their order (`output::tresca`'s module doc).
pub(super) fn covered(contact: bool, errors: bool) -> String {
    let mut v = vec!["times", "u", "energy"];
    v.extend(["steps/iterations", "steps/residual", "steps/n_stick", "steps/n_slip", "steps/wall_time"]);
    if contact {
        v.extend(["contact/slip", "contact/sigma_t", "contact/state", "contact/mu", "contact/dof"]);
    }
    if errors {
        v.extend(["errors/energy", "errors/h1", "errors/l2"]);
    }
    let audit = AUDIT.map(|a| format!("steps/{a}"));
    v.into_iter().map(String::from).chain(audit).collect::<Vec<_>>().join(", ")
}

/// The checksums of the buffered rows `b`, in step order; `(contact, errors, audit)` say which of
/// those optional series the file's checksums cover.
pub(super) fn rows_checksums(b: &Rows, (contact, errors, audit): (bool, bool, bool)) -> Vec<u64> {
    use bytemuck::cast_slice as c;
    let mut v: Vec<&[u8]> = vec![
        c(&b.times),
        c(&b.u),
        c(&b.energy),
        c(&b.iterations),
        c(&b.residual),
        c(&b.n_stick),
        c(&b.n_slip),
        c(&b.wall),
    ];
    if contact {
        v.extend([c(&b.slip), c(&b.sigma_t), &b.state[..], c(&b.mu), c(&b.dof)]);
    }
    if errors {
        v.extend(b.errors.iter().map(|e| c(e)));
    }
    if audit {
        v.extend(b.audit.iter().map(|a| c(a)));
    }
    step_checksums(&v, b.count)
}

/// The first of the `completed` stored steps whose rows of `series` (in the checksum's order) do not
/// match their `stored` checksum, if any.
pub(super) fn first_corrupt(stored: &[u64], series: &[&mut Series], completed: usize) -> hdf5::Result<Option<usize>> {
    // blocks of steps of about 64 MB, so that a file larger than memory is verified too
    let per_step = series.iter().map(|s| s.step_bytes()).sum::<usize>().max(1);
    let block = ((64 << 20) / per_step).max(1);
    for first in (0..completed).step_by(block) {
        let count = block.min(completed - first);
        let bytes = series.iter().map(|s| s.read_bytes(first, count)).collect::<hdf5::Result<Vec<_>>>()?;
        let views: Vec<&[u8]> = bytes.iter().map(|b| &b[..]).collect();
        let sums = step_checksums(&views, count);
        if let Some(k) = sums.iter().zip(&stored[first..]).position(|(a, b)| a != b) {
            return Ok(Some(first + k));
        }
    }
    Ok(None)
}

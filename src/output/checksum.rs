//! The per-step checksums of `tresca/steps/checksum` (the layout: `output::tresca`'s module doc): XXH64
//! (seed 0) of each step's rows of every series it covers, in order, as little-endian bytes; the
//! attribute [`COVERS`] names those series. `tresca_py.checksum` computes the same.

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

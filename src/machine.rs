//! What this machine has: the memory available to a new allocation and the free space of a file system.
//! Read by the pre-run estimate (`scene::budget`) and by the factorisation, which checks the exact size of
//! the factor before it allocates it (`solve::cholesky`).

use std::path::Path;

/// MemAvailable of `/proc/meminfo`, bytes (`None` where there is no such file).
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Hand the heap memory freed so far back to the system (glibc's `malloc_trim`): glibc keeps freed
/// memory below its top chunk and in its arenas for reuse, so after the set-up's temporaries (patterns,
/// graph, ordering, the upper triangle of K) a process holds pages nothing uses. Called before the
/// numeric factorisation, whose factor is the run's largest allocation. Elsewhere (no glibc) nothing.
pub fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases free memory of the allocator; no pointer is involved.
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Free bytes (for unprivileged users) of the file system holding `dir` or its nearest existing ancestor.
pub fn available_disk(dir: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let mut d = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
    while !d.exists() {
        d = d.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    }
    let c = std::ffi::CString::new(d.as_os_str().as_bytes()).ok()?;
    let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
    // SAFETY: `c` is a NUL-terminated path and `st` a statvfs the call fills.
    if unsafe { libc::statvfs(c.as_ptr(), &mut st) } != 0 {
        return None;
    }
    Some((st.f_bavail as u64).saturating_mul(st.f_frsize as u64))
}

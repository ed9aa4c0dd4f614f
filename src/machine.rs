//! What this machine has: the memory available to a new allocation and the free space of a file system.
//! Read by the pre-run estimate (`scene::budget`) and by the factorisation, which checks the exact size of
//! the factor before it allocates it (`solve::cholesky`).
//!
//! The memory a process can have is the least of three bounds: MemAvailable of `/proc/meminfo` (the
//! machine), what the address-space limit leaves (`ulimit -v`, RLIMIT_AS, less the process's VmSize), and
//! what the memory limit of its cgroup leaves (v2 `memory.max`, v1 `memory.limit_in_bytes`, of its group
//! and every ancestor, less the group's usage without its inactive file cache, which the kernel reclaims
//! first). The last two are hard: an allocation past them fails whatever `--max-memory` says.

use std::path::{Path, PathBuf};

/// What each bound is called in a refusal ("… B of memory needed, … B {what}").
const MACHINE: &str = "is available on this machine";
const ADDRESS_SPACE: &str = "is left under this process's address-space limit (ulimit -v)";
const CGROUP: &str = "is left under the memory limit of this process's cgroup";

/// The memory a new allocation can have, bytes: the least of the three bounds of the module doc (`None`
/// where none is known).
pub fn available_memory() -> Option<u64> {
    memory_left().map(|(b, _)| b)
}

/// [`available_memory`] with the words that name the bound it is.
pub fn memory_left() -> Option<(u64, &'static str)> {
    [mem_available().map(|b| (b, MACHINE)), hard_memory_left()].into_iter().flatten().min_by_key(|&(b, _)| b)
}

/// The least of the hard bounds (address space, cgroup), with the words that name it; `None` without any.
pub fn hard_memory_left() -> Option<(u64, &'static str)> {
    let aspace = address_space_left().map(|b| (b, ADDRESS_SPACE));
    [aspace, cgroup_left().map(|b| (b, CGROUP))].into_iter().flatten().min_by_key(|&(b, _)| b)
}

/// The number after `key` in a `key value` text (`/proc/meminfo`, `/proc/self/status`, `memory.stat`).
fn field(text: &str, key: &str) -> Option<u64> {
    let line = text.lines().find(|l| l.split_whitespace().next() == Some(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// MemAvailable of `/proc/meminfo`, bytes.
fn mem_available() -> Option<u64> {
    Some(field(&std::fs::read_to_string("/proc/meminfo").ok()?, "MemAvailable:")? * 1024)
}

/// RLIMIT_AS less the process's VmSize, bytes; `None` without a limit.
fn address_space_left() -> Option<u64> {
    let mut lim = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit fills the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut lim) } != 0 || lim.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    let vm = field(&std::fs::read_to_string("/proc/self/status").ok()?, "VmSize:").unwrap_or(0) * 1024;
    Some(lim.rlim_cur.saturating_sub(vm))
}

/// What the memory limits of the process's cgroup (its group and every ancestor, v1 or v2) leave.
fn cgroup_left() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/cgroup").ok()?;
    let mut least = None::<u64>;
    for line in text.lines() {
        let mut parts = line.splitn(3, ':');
        let (Some(id), Some(ctl), Some(path)) = (parts.next(), parts.next(), parts.next()) else { continue };
        let (root, names) = if id == "0" && ctl.is_empty() {
            ("/sys/fs/cgroup", ["memory.max", "memory.current", "inactive_file"])
        } else if ctl.split(',').any(|c| c == "memory") {
            ("/sys/fs/cgroup/memory", ["memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file"])
        } else {
            continue;
        };
        let mut dir = PathBuf::from(root).join(path.trim_start_matches('/'));
        loop {
            if let Some(left) = group_left(&dir, names) {
                least = Some(least.map_or(left, |l| l.min(left)));
            }
            if dir.as_path() == Path::new(root) || !dir.pop() {
                break;
            }
        }
    }
    least
}

/// limit − (usage − inactive file cache) of one cgroup directory; `None` without a limit (`max`, or v1's
/// near 2⁶³ "unlimited").
fn group_left(dir: &Path, [max, current, inactive]: [&str; 3]) -> Option<u64> {
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).ok();
    let limit: u64 = read(max)?.trim().parse().ok().filter(|&l: &u64| l < 1 << 62)?;
    let usage: u64 = read(current)?.trim().parse().ok()?;
    let cache = read("memory.stat").and_then(|t| field(&t, inactive)).unwrap_or(0);
    Some(limit.saturating_sub(usage.saturating_sub(cache)))
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

/// `n` zeros, written: a buffer that is read before it is written (`+=` into it) should not start as
/// `vec![0.0; n]`, whose fresh pages the kernel maps to its shared zero page on the first read; the first
/// write then copies that page and flushes the TLB of every core running the process, an interrupt to
/// each (on the project's 2-core VMs K's values took 1.1 s of CPU beside the ordering thread instead of
/// 0.45 s; reference/performance.md §9). Written zeros fault each page once, writable.
pub fn written_zeros(n: usize) -> Vec<f64> {
    let mut v = Vec::with_capacity(n);
    v.resize(n, 0.0);
    v
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

/// CPU seconds the calling thread has used (`CLOCK_THREAD_CPUTIME_ID`; 0 where the clock cannot be read).
pub fn thread_cpu_seconds() -> f64 {
    // SAFETY: a timespec is plain data, which clock_gettime fills.
    let (rc, ts) = unsafe {
        let mut ts: libc::timespec = std::mem::zeroed();
        (libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts), ts)
    };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

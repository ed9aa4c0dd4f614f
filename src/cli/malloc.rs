//! glibc's allocator: tuned once at start, its free pages handed back before the run's last serial work.

/// glibc's malloc keeps freed memory for reuse instead of handing it back at once: blocks up to 32 MiB
/// come from the heap (not one mmap each, returned on free and faulted in again page by page on the
/// next allocation), the heap grows 64 MiB at a time and is trimmed only beyond 1 GiB. The set-up
/// allocates and frees many vectors of the mesh's size; at 24,640 unknowns (Example 5.1, n = 64) this
/// cuts the page faults and the CPU time. (jemalloc with huge
/// pages cut the faults further but tripled the system time of the 196,608-unknown run, by huge-page
/// compaction.) Peak memory is the same; numbers do not depend on it.
pub fn tune() {
    // SAFETY: mallopt only sets allocator parameters; called before any thread exists.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 32 << 20);
        libc::mallopt(libc::M_TOP_PAD, 64 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 1 << 30);
    }
}

/// Hand the heap's free pages back to the system now (`malloc_trim`), instead of at the process's exit,
/// where freeing them is the last serial work of a run (about 57 MB, 5–8 ms at 24,640 unknowns). Called
/// while another thread still works (the results writer), so the two overlap.
pub fn hand_back_memory() {
    // SAFETY: malloc_trim only returns free pages of glibc's arenas to the system; it is thread-safe.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    unsafe {
        libc::malloc_trim(0);
    }
}

//! A zeroed `f64` buffer on fresh anonymous pages, whose page faults a second thread can take ahead
//! of the thread that fills it.
//!
//! On the 2-core VMs this project runs on, first-touching memory costs about 2.4 µs a 4 KiB page
//! (17 ms for the 29 MB of a 24,640-unknown Cholesky factor, a third of its numeric factorisation).
//! [`Pages::populate`] asks the kernel to map the pages (`madvise(MADV_POPULATE_WRITE)`, Linux ≥ 5.14)
//! from the back of the buffer to the front, in 2 MiB pieces, while the owner writes from the front:
//! the kernel only maps zero-filled pages where none is mapped and never touches the contents of a
//! mapped page, so this runs safely beside writes to the slice (no Rust reference to the memory is
//! made by the populating thread). On kernels without it the call fails and the owner faults the
//! pages itself, as before; the values are the same either way.
//!
//! Buffers of [`HUGE_MIN`] to [`HUGE_MAX`] bytes are placed on 2 MiB boundaries and marked for
//! transparent huge pages (`madvise(MADV_HUGEPAGE)`), where the kernel offers them (`enabled` = `always`
//! or `madvise`): a 29 MB factor then takes 15 faults of 2 MiB instead of 7,300 of 4 KiB. The kernel
//! still zero-fills each page, so the contents are the same; where it has no free huge page it falls
//! back to 4 KiB pages. Above [`HUGE_MAX`] huge pages made the factor slower on the project's VMs (the
//! system time doubled, nearly all of it zeroing the huge pages: these VMs hand freed memory back to the
//! host, free page reporting, and large runs of huge pages then come from memory the host must provide
//! anew), hence the upper bound (figures in CHANGELOG.md). Only this one large
//! buffer, filled once and read to the end of the run, is marked: huge pages for the whole heap (glibc's
//! `hugetlb` tunable, mimalloc, jemalloc) made small runs slower at times and tripled the system time of
//! the 196,608-unknown run.

use std::ops::{Deref, DerefMut};

/// Bytes per `madvise` call of [`Pages::populate`]: one huge page.
const PIECE: usize = HUGE;
/// A transparent huge page (x86-64).
const HUGE: usize = 2 << 20;
/// Buffers of at least this many bytes and at most [`HUGE_MAX`] are backed by transparent huge pages
/// (see the module doc).
pub const HUGE_MIN: usize = 4 << 20;
/// Above this many bytes a buffer stays on 4 KiB pages (see the module doc: 163 MB gained, 347 MB lost).
pub const HUGE_MAX: usize = 192 << 20;

/// `len` zeroed `f64` on their own anonymous mapping.
pub struct Pages {
    ptr: *mut f64,
    len: usize,
}

// SAFETY: `Pages` owns its mapping exclusively, like a `Vec<f64>`; shared access is through `&[f64]`.
unsafe impl Send for Pages {}
unsafe impl Sync for Pages {}

/// The address range of a [`Pages`], for [`Pages::populate`] on another thread.
#[derive(Clone, Copy)]
pub struct Range {
    addr: usize,
    bytes: usize,
}

impl Pages {
    /// A zeroed buffer of `len` values; `None` if the mapping fails (out of memory). From [`HUGE_MIN`]
    /// to [`HUGE_MAX`] bytes, on 2 MiB boundaries and marked for transparent huge pages (see the module
    /// doc).
    pub fn zeroed(len: usize) -> Option<Pages> {
        if len == 0 {
            return Some(Pages { ptr: std::ptr::NonNull::dangling().as_ptr(), len });
        }
        let bytes = len.checked_mul(8)?;
        let huge = (HUGE_MIN..=HUGE_MAX).contains(&bytes);
        // a huge-page buffer is cut out of a mapping one huge page longer, at its first 2 MiB boundary
        let total = if huge { bytes.checked_add(HUGE)? } else { bytes };
        let p = map(total)?;
        if !huge {
            return Some(Pages { ptr: p.cast(), len });
        }
        let (base, start) = (p as usize, (p as usize).next_multiple_of(HUGE));
        let (end, map_end) = ((start + bytes).next_multiple_of(4096), base + total);
        // SAFETY: [base, start) and [end, map_end) lie in the mapping just made and hold no data; what
        // stays mapped is [start, end), which Drop unmaps. madvise only sets an advice on that range.
        unsafe {
            if start > base {
                libc::munmap(p, start - base);
            }
            if map_end > end {
                libc::munmap(end as *mut libc::c_void, map_end - end);
            }
            // an advice: where it is refused (THP disabled), the pages are 4 KiB ones, as without it
            libc::madvise(start as *mut libc::c_void, bytes, libc::MADV_HUGEPAGE);
        }
        Some(Pages { ptr: start as *mut f64, len })
    }

    /// The buffer's address range.
    pub fn range(&self) -> Range {
        Range { addr: self.ptr as usize, bytes: self.len * 8 }
    }

    /// Map the pages of `r` back to front, a [`PIECE`] at a time, pieces aligned to the buffer's start
    /// (so to huge pages, see the module doc); stops at the first failure.
    pub fn populate(r: Range) {
        let mut end = r.bytes;
        while end > 0 {
            let start = (end - 1) / PIECE * PIECE;
            // SAFETY: the range lies within a live mapping of its `Pages` (the caller joins this thread
            // before the buffer can be dropped); MADV_POPULATE_WRITE does not change mapped contents.
            let rc =
                unsafe { libc::madvise((r.addr + start) as *mut libc::c_void, end - start, libc::MADV_POPULATE_WRITE) };
            if rc != 0 {
                return;
            }
            end = start;
        }
    }
}

/// A fresh private anonymous mapping of `bytes` bytes (zero-filled by the kernel); `None` if it fails.
fn map(bytes: usize) -> Option<*mut libc::c_void> {
    // SAFETY: a new mapping at an address of the kernel's choosing; checked for failure.
    let p = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            bytes,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS,
            -1,
            0,
        )
    };
    (p != libc::MAP_FAILED).then_some(p)
}

impl Deref for Pages {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: `len` initialised (zero-filled) values in a mapping owned by self.
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl DerefMut for Pages {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as in `deref`, with exclusive access through &mut self.
        unsafe { std::slice::from_raw_parts_mut(self.ptr, self.len) }
    }
}

impl Drop for Pages {
    fn drop(&mut self) {
        if self.len > 0 {
            // SAFETY: the mapping made in `zeroed`, unmapped once.
            unsafe { libc::munmap(self.ptr.cast(), self.len * 8) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn populating_beside_writes_keeps_the_written_values() {
        // 3 MiB + a partial page: several pieces, an unaligned end; then a huge-page buffer
        for len in [(3 << 17) + 100, (HUGE_MIN + (5 << 20)) / 8 + 100] {
            populated_beside_writes(len);
        }
        let empty = Pages::zeroed(0).unwrap();
        assert!(empty.is_empty());
        Pages::populate(empty.range());
    }

    fn populated_beside_writes(len: usize) {
        let mut p = Pages::zeroed(len).unwrap();
        if (HUGE_MIN..=HUGE_MAX).contains(&(len * 8)) {
            assert_eq!(p.as_ptr() as usize % HUGE, 0, "a huge-page buffer starts on a 2 MiB boundary");
        }
        assert!(p.iter().all(|&v| v == 0.0));
        let r = p.range();
        std::thread::scope(|s| {
            s.spawn(move || Pages::populate(r));
            p.iter_mut().enumerate().for_each(|(i, v)| *v = i as f64);
        });
        assert!(p.iter().enumerate().all(|(i, &v)| v == i as f64));
        // populating again changes nothing
        Pages::populate(p.range());
        assert!(p.iter().enumerate().all(|(i, &v)| v == i as f64));
    }
}

//! Large output buffers backed by transparent huge pages: the one place the library speaks to
//! the operating system (a hint, `madvise(MADV_HUGEPAGE)` on Linux, ignored elsewhere; no
//! number a caller sees depends on it).
//!
//! A large vector is fresh memory from the kernel, faulted in page by page when first written:
//! `risk --map` 4096 x 4096 (two maps of 128 MiB) spent 0.17 s of its 0.5 s CPU time in the
//! kernel with 4 KiB pages (`/usr/bin/time -v`, shared 2-core machine); advised for 2 MiB
//! pages, 0.03 to 0.10 s, and the whole 1024 x 1024 run fell from 44 to 36 ms of CPU time
//! (`perf stat`, 5 runs each). A 2048 x 2048 phase map from Python writes 36 MB into fresh
//! memory, 9000 page faults with 4 KiB pages and a few dozen with 2 MiB pages.

/// `n` zeros, the buffer advised for transparent huge pages before it is first touched.
pub fn zeroed(n: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    advise_huge_pages(v.as_mut_ptr().cast(), n * std::mem::size_of::<f64>());
    v
}

/// An empty vector with room for `n` values, advised for transparent huge pages before
/// anything touches it; the caller writes every value through `spare_capacity_mut` (in
/// parallel, without zeroing first) and then sets the length.
pub fn uninit<T>(n: usize) -> Vec<T> {
    let mut v: Vec<T> = Vec::with_capacity(n);
    advise_huge_pages(v.as_mut_ptr().cast(), n * std::mem::size_of::<T>());
    v
}

/// Asks the kernel to back `[ptr, ptr + bytes)` with transparent huge pages where it covers
/// whole 2 MiB pages (a hint: ignored where unsupported, and below two such pages).
fn advise_huge_pages(ptr: *mut u8, bytes: usize) {
    const HUGE: usize = 2 << 20;
    if bytes < 2 * HUGE {
        return;
    }
    #[cfg(target_os = "linux")]
    {
        let start = (ptr as usize).next_multiple_of(HUGE);
        let end = (ptr as usize + bytes) / HUGE * HUGE;
        if end > start {
            // SAFETY: the range lies inside one live allocation of this process; MADV_HUGEPAGE
            // only changes how its pages are backed, never their contents.
            unsafe { libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE) };
        }
    }
}

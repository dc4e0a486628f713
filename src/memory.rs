//! Giving freed heap memory back to the operating system between pipeline stages.

/// Returns the heap's free memory to the operating system. The system allocator
/// (glibc) keeps what a stage frees for later small allocations, but the next stage's
/// big buffers are mapped afresh and cannot use it: the edge schemes free every
/// face's flaps (about 600 MiB at a million faces) just before the flatten stage
/// fills its arena, and without this that memory stays resident to the end of the
/// job (on the 1M-face quad-edge scale run, about 400 MiB of a 1.9 GiB peak). A no-op
/// where the allocator is not glibc's.
pub fn release_freed() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim takes no pointers; it only hands free pages of the heap
    // back to the kernel and is safe to call at any time, from any thread.
    unsafe {
        libc::malloc_trim(0);
    }
}

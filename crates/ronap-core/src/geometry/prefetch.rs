//! Cache-line prefetch hints: they change when memory arrives, never what a program computes.
//!
//! Stepping a thousand environments reads a thousand scenes, more than the caches hold, and each
//! step's first query waits on a chain of loads (the scene, its bin, the bin's list, the boxes).
//! Asking for those lines a few environments ahead lets the waits overlap the work in between.

/// Asks for the cache line holding `value` (nothing where the processor has no such hint).
#[inline(always)]
pub(crate) fn line<T>(value: &T) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse"))]
    safe_arch::prefetch_t0(value);
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse")))]
    let _ = value;
}

/// Asks for every cache line `values` covers.
#[inline]
pub(crate) fn lines<T>(values: &[T]) {
    const LINE: usize = 64;
    let step = (LINE / std::mem::size_of::<T>().max(1)).max(1);
    for v in values.iter().step_by(step) {
        line(v);
    }
    if let Some(last) = values.last() {
        line(last);
    }
}

//! A hint to bring a cache line in before it is read: for the traversal's
//! next child (`traverse.rs`) and for the build's passes over ranges of
//! triangles (`binning.rs`). Only a hint: it never faults, whatever the
//! address, and nothing depends on it but time.

/// Asks for the cache line holding `address` in every cache level.
#[inline(always)]
pub(super) fn prefetch_line<T>(address: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch never faults; it is a hint for any address.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(address.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = address;
}

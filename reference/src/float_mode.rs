//! Flush-to-zero and denormals-are-zero, which Embree asks every thread that
//! calls it to enable (Embree's API documentation, "Performance
//! Recommendations": MXCSR control and status register).
//!
//! The mode is per thread: callers enable it on each thread that traces
//! (the ray queries in this crate do not touch it).

/// MXCSR bit 15: flush denormal results to zero.
#[cfg(target_arch = "x86_64")]
const MXCSR_FLUSH_TO_ZERO: u32 = 1 << 15;
/// MXCSR bit 6: treat denormal inputs as zero.
#[cfg(target_arch = "x86_64")]
const MXCSR_DENORMALS_ARE_ZERO: u32 = 1 << 6;

/// Turns on flush-to-zero and denormals-are-zero for the calling thread.
/// A no-op on targets other than x86_64.
pub fn enable_flush_to_zero_and_denormals_are_zero() {
    #[cfg(target_arch = "x86_64")]
    write_mxcsr(read_mxcsr() | MXCSR_FLUSH_TO_ZERO | MXCSR_DENORMALS_ARE_ZERO);
}

/// Whether both modes are on for the calling thread (always `false` on
/// targets other than x86_64).
pub fn flush_to_zero_and_denormals_are_zero_enabled() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        let both = MXCSR_FLUSH_TO_ZERO | MXCSR_DENORMALS_ARE_ZERO;
        read_mxcsr() & both == both
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

#[cfg(target_arch = "x86_64")]
fn read_mxcsr() -> u32 {
    let mut csr = 0u32;
    // SAFETY: `stmxcsr` stores the 32-bit MXCSR into the given, writable word.
    unsafe {
        std::arch::asm!("stmxcsr [{}]", in(reg) &mut csr, options(nostack, preserves_flags));
    }
    csr
}

#[cfg(target_arch = "x86_64")]
fn write_mxcsr(csr: u32) {
    // SAFETY: `ldmxcsr` loads MXCSR from the given word; only the mode bits
    // of a value read from MXCSR were changed, so no reserved bit is set.
    unsafe {
        std::arch::asm!("ldmxcsr [{}]", in(reg) &csr, options(nostack, readonly, preserves_flags));
    }
}

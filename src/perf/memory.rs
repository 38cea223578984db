//! The peak memory a build takes: the process's resident high-water mark
//! (`VmHWM` in `/proc/self/status`) reset before the build (writing `5` to
//! `/proc/self/clear_refs`, Linux 4.0 and later) and read after it, less
//! what was resident before. Where either file cannot be used, the peak is
//! not known. Memory the allocator freed but kept resident (a previous
//! build's, say) would let a build grow without raising the mark, so on
//! glibc it is handed back first (`malloc_trim(3)`).

/// Runs `f`; returns its value and the bytes its run added to the
/// process's peak resident size, if the system can tell.
pub fn peak_during<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    release_free_heap();
    let before = reset_peak().then(|| status_bytes("VmRSS:")).flatten();
    let value = f();
    let peak = before.and_then(|before| Some(status_bytes("VmHWM:")?.saturating_sub(before)));
    (value, peak)
}

/// Returns the heap's free pages to the system, so that reusing them
/// shows in the resident size again.
fn release_free_heap() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        unsafe extern "C" {
            fn malloc_trim(pad: usize) -> std::ffi::c_int;
        }
        // SAFETY: malloc_trim only releases free memory; it has no
        // preconditions and glibc makes it thread-safe.
        unsafe {
            malloc_trim(0);
        }
    }
}

/// Resets the resident high-water mark to the current resident size.
fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// A `kB` field of `/proc/self/status`, in bytes.
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line[field.len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_build_reusing_freed_memory_still_shows_in_the_peak() {
        let size = 64 << 20;
        // Many blocks below glibc's mmap threshold land in the heap and stay
        // there, resident, once freed.
        let blocks = |n: usize| -> Vec<Vec<u8>> { (0..n).map(|_| vec![1u8; 64 << 10]).collect() };
        drop(blocks(size / (64 << 10)));
        let (kept, peak) = peak_during(|| blocks(size / (64 << 10)));
        assert_eq!(kept.len() * (64 << 10), size);
        if let Some(peak) = peak {
            assert!(peak >= size as u64 * 9 / 10, "{peak}");
        }
    }

    #[test]
    fn a_large_allocation_shows_in_the_peak() {
        let size = 256 << 20;
        let (sum, peak) = peak_during(|| {
            let buffer = vec![1u8; size];
            buffer.iter().map(|&b| b as u64).sum::<u64>()
        });
        assert_eq!(sum, size as u64);
        if let Some(peak) = peak {
            assert!(peak >= size as u64 * 9 / 10, "{peak}");
        } else {
            assert!(!std::path::Path::new("/proc/self/clear_refs").exists());
        }
    }
}

//! The peak memory a build takes: the process's resident high-water mark
//! (`VmHWM` in `/proc/self/status`) reset before the build (writing `5` to
//! `/proc/self/clear_refs`, Linux 4.0 and later) and read after it, less
//! what was resident before. Where either file cannot be used, the peak is
//! not known.

/// Runs `f`; returns its value and the bytes its run added to the
/// process's peak resident size, if the system can tell.
pub fn peak_during<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    let before = reset_peak().then(|| status_bytes("VmRSS:")).flatten();
    let value = f();
    let peak = before.and_then(|before| Some(status_bytes("VmHWM:")?.saturating_sub(before)));
    (value, peak)
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

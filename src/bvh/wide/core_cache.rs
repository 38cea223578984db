//! The size of one core's L2 cache, which decides whether a traversal
//! prefetches: a tree that fits in it is served at L2 latency anyway, and
//! the prefetch instructions are then pure overhead (on the Xeon host,
//! leaving them out made the Cornell box, the monkey and dragon-11k 2–4%
//! faster, dragon-203k unchanged and dragon-871k 3–5% slower).

use std::sync::OnceLock;

/// Bytes of the L2 cache of the first CPU, read once; `None` where the
/// system does not say (outside Linux, or without its cache directory).
pub(crate) fn l2_bytes() -> Option<usize> {
    static L2: OnceLock<Option<usize>> = OnceLock::new();
    *L2.get_or_init(read_l2_bytes)
}

/// Linux lists each cache level of a CPU under `cache/index*` with its
/// `level`, `type` and `size` ("2048K").
fn read_l2_bytes() -> Option<usize> {
    let caches = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache").ok()?;
    caches.flatten().find_map(|entry| {
        let field = |name: &str| std::fs::read_to_string(entry.path().join(name)).ok();
        let unified_or_data = matches!(field("type")?.trim(), "Unified" | "Data");
        (field("level")?.trim() == "2" && unified_or_data)
            .then(|| parse_size(field("size")?.trim()))
            .flatten()
    })
}

/// A size as Linux prints it: a count of bytes with an optional `K` or
/// `M` suffix.
fn parse_size(text: &str) -> Option<usize> {
    let (digits, unit) = match text.strip_suffix('K') {
        Some(digits) => (digits, 1 << 10),
        None => match text.strip_suffix('M') {
            Some(digits) => (digits, 1 << 20),
            None => (text, 1),
        },
    };
    digits.parse::<usize>().ok()?.checked_mul(unit)
}

#[cfg(test)]
mod tests {
    use super::parse_size;

    #[test]
    fn sizes_parse_with_their_units() {
        assert_eq!(parse_size("2048K"), Some(2 << 20));
        assert_eq!(parse_size("1M"), Some(1 << 20));
        assert_eq!(parse_size("512"), Some(512));
        assert_eq!(parse_size("lots"), None);
        assert_eq!(parse_size(""), None);
    }
}

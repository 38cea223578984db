//! The sizes of the caches of the first CPU, as Linux reports them, which
//! decide how much a traversal prefetches ([`super::prefetch::Prefetch`]).

use std::sync::OnceLock;

/// Bytes of a core's L2 cache and of the last-level cache; `None` where
/// the system does not say (outside Linux, or without its cache
/// directory).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct CacheSizes {
    pub l2: Option<usize>,
    pub last_level: Option<usize>,
}

/// The first CPU's cache sizes, read once.
pub(crate) fn cache_sizes() -> CacheSizes {
    static SIZES: OnceLock<CacheSizes> = OnceLock::new();
    *SIZES.get_or_init(read_cache_sizes)
}

/// Linux lists each cache of a CPU under `cache/index*` with its `level`,
/// `type` and `size` ("2048K"); instruction caches are left out.
fn read_cache_sizes() -> CacheSizes {
    let Ok(caches) = std::fs::read_dir("/sys/devices/system/cpu/cpu0/cache") else {
        return CacheSizes::default();
    };
    let levels: Vec<(u32, usize)> = caches
        .flatten()
        .filter_map(|entry| {
            let field = |name: &str| std::fs::read_to_string(entry.path().join(name)).ok();
            let unified_or_data = matches!(field("type")?.trim(), "Unified" | "Data");
            let level = field("level")?.trim().parse().ok()?;
            unified_or_data.then_some((level, parse_size(field("size")?.trim())?))
        })
        .collect();
    CacheSizes {
        l2: levels.iter().find(|(level, _)| *level == 2).map(|c| c.1),
        last_level: levels.iter().max_by_key(|(level, _)| *level).map(|c| c.1),
    }
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

//! Hints to bring cache lines in before they are read: for the children a
//! traversal pushes (`traverse.rs`), as much as the tree's size against
//! the caches makes pay ([`Prefetch`]), for the child references of every
//! node it enters, and for the build's passes over ranges of triangles
//! (`binning.rs`). Only hints: a prefetch never
//! faults, whatever the address, and nothing depends on it but time.

use super::core_cache::{CacheSizes, cache_sizes};

/// Which of the children a node pushes the traversal asks for ahead, so
/// that their loads overlap the work on the child visited first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Prefetch {
    /// None: the tree fits in a core's L2 cache, which serves its loads
    /// at its latency anyway (on the Xeon host, prefetching made the
    /// Cornell box, the monkey and dragon-11k 1–4% slower).
    Nothing,
    /// The one popped next, for trees larger than L2 that fit in the
    /// last-level cache (dragon-48k to dragon-871k on the Xeon host:
    /// every child made dragon-48k's diffuse rays 4% slower), and where
    /// the caches are not reported.
    NextPopped,
    /// Every child pushed, for trees larger than the last-level cache,
    /// where each child's first load goes to memory (dragon-14m's 780 MB
    /// on the Xeon host's 480 MB: 2–5% faster than the next popped only).
    EveryPushed,
}

impl Prefetch {
    /// The prefetching for a tree of `bytes` on this machine.
    pub fn for_tree(bytes: usize) -> Prefetch {
        Self::for_tree_in(bytes, cache_sizes())
    }

    fn for_tree_in(bytes: usize, caches: CacheSizes) -> Prefetch {
        match caches {
            CacheSizes { l2: Some(l2), .. } if bytes <= l2 => Prefetch::Nothing,
            CacheSizes {
                last_level: Some(last),
                ..
            } if bytes > last => Prefetch::EveryPushed,
            _ => Prefetch::NextPopped,
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    const MIB: usize = 1 << 20;

    #[test]
    fn the_tree_against_the_caches_decides_what_is_prefetched() {
        let caches = CacheSizes {
            l2: Some(2 * MIB),
            last_level: Some(480 * MIB),
        };
        let choice = |bytes| Prefetch::for_tree_in(bytes, caches);
        assert_eq!(choice(2 * MIB), Prefetch::Nothing);
        assert_eq!(choice(2 * MIB + 1), Prefetch::NextPopped);
        assert_eq!(choice(480 * MIB), Prefetch::NextPopped);
        assert_eq!(choice(480 * MIB + 1), Prefetch::EveryPushed);
        // Unreported sizes keep the middle course.
        let unknown = CacheSizes::default();
        assert_eq!(Prefetch::for_tree_in(1, unknown), Prefetch::NextPopped);
        assert_eq!(
            Prefetch::for_tree_in(usize::MAX, unknown),
            Prefetch::NextPopped
        );
    }
}

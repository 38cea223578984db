//! Storage for the arrays a traversal reads at random (nodes, triangle
//! blocks) and the build's largest temporary (the triangles' boxes),
//! backed by 2 MiB pages where the kernel offers them: on Linux
//! with transparent huge pages in `madvise` mode, `madvise(MADV_HUGEPAGE)`
//! before the first write. A tree of hundreds of megabytes then costs a
//! TLB miss per 2 MiB instead of per 4 KiB page, as Embree's own
//! allocator arranges (its `hugepages` setting).

/// An empty vector with room for `capacity` elements, its storage advised
/// to use huge pages. The advice is only that: where the kernel declines
/// it, or outside Linux, the storage is ordinary.
pub(crate) fn vec_with_capacity<T>(capacity: usize) -> Vec<T> {
    let vec: Vec<T> = Vec::with_capacity(capacity);
    advise(vec.as_ptr().cast(), capacity * std::mem::size_of::<T>());
    vec
}

/// Below this, a huge page could not be filled.
const HUGE_PAGE: usize = 2 << 20;

#[cfg(target_os = "linux")]
fn advise(start: *const u8, bytes: usize) {
    const PAGE: usize = 4096;
    if bytes < HUGE_PAGE {
        return;
    }
    let first = (start as usize).next_multiple_of(PAGE);
    let end = (start as usize + bytes) / PAGE * PAGE;
    // SAFETY: the range lies within one live allocation of this process,
    // rounded inwards to whole pages; MADV_HUGEPAGE changes no contents and
    // a refusal (an error return) leaves the pages as they were.
    unsafe {
        libc::madvise(first as *mut libc::c_void, end - first, libc::MADV_HUGEPAGE);
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_start: *const u8, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    /// Advised or not, the storage holds what is written to it, small or
    /// larger than a huge page.
    #[test]
    fn the_vector_is_empty_with_its_room_and_holds_what_is_pushed() {
        for capacity in [0, 10, 3 * HUGE_PAGE / 8 + 5] {
            let mut vec = vec_with_capacity::<u64>(capacity);
            assert!(vec.is_empty() && vec.capacity() >= capacity);
            vec.extend((0..capacity as u64).map(|i| i * 3));
            assert!(vec.iter().enumerate().all(|(i, &v)| v == 3 * i as u64));
            assert_eq!(
                vec.capacity(),
                vec_with_capacity::<u64>(capacity).capacity()
            );
        }
    }
}

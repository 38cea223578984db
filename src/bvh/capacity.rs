//! What a build can take, checked before it starts: the triangle count
//! the tree's indices can address (node, block and triangle indices are
//! 32-bit), and the memory the build is about to need against what the
//! machine has available, so a mesh too large fails with a clear error
//! instead of an overflow or the out-of-memory killer halfway through.

use thiserror::Error;

#[derive(Clone, Debug, PartialEq, Eq, Error)]
pub enum CapacityError {
    #[error("{triangles} triangles: the {tree} indexes at most {limit}")]
    TooManyTriangles {
        triangles: usize,
        limit: usize,
        tree: &'static str,
    },
    #[error(
        "{triangles} triangles: building the {tree} needs about {} MiB, \
         and only {} MiB of memory is available",
        needed >> 20,
        available >> 20
    )]
    OutOfMemory {
        triangles: usize,
        tree: &'static str,
        needed: u64,
        available: u64,
    },
}

/// What one kind of tree can index and needs to build.
#[derive(Clone, Copy, Debug)]
pub(super) struct Needs {
    pub tree: &'static str,
    /// The most triangles its indices address.
    pub max_triangles: usize,
    /// Memory per triangle while it builds (working copies and the tree),
    /// with room to spare over the typical.
    pub bytes_per_triangle: u64,
}

/// Builds needing less than this skip the memory check.
const CHECKED_FROM_BYTES: u64 = 256 << 20;

impl Needs {
    /// Whether a mesh of `triangles` triangles can be built here.
    pub fn check(&self, triangles: usize) -> Result<(), CapacityError> {
        self.check_with(triangles, available_memory)
    }

    /// [`Needs::check`] with the available memory from `available`
    /// (`None`: unknown, not checked), asked only for large builds.
    fn check_with(
        &self,
        triangles: usize,
        available: impl FnOnce() -> Option<u64>,
    ) -> Result<(), CapacityError> {
        if triangles > self.max_triangles {
            return Err(CapacityError::TooManyTriangles {
                triangles,
                limit: self.max_triangles,
                tree: self.tree,
            });
        }
        let needed = triangles as u64 * self.bytes_per_triangle;
        if needed < CHECKED_FROM_BYTES {
            return Ok(());
        }
        match available() {
            Some(available) if available < needed => Err(CapacityError::OutOfMemory {
                triangles,
                tree: self.tree,
                needed,
                available,
            }),
            _ => Ok(()),
        }
    }
}

/// The memory the system can give this process without swapping:
/// `MemAvailable` of `/proc/meminfo` (Linux); `None` elsewhere.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    const NEEDS: Needs = Needs {
        tree: "test tree",
        max_triangles: (1 << 31) - 1,
        bytes_per_triangle: 128,
    };

    #[test]
    fn counts_beyond_the_indices_are_refused_before_anything_else() {
        let error = NEEDS.check_with(1 << 32, || Some(u64::MAX)).unwrap_err();
        assert_eq!(
            error.to_string(),
            "4294967296 triangles: the test tree indexes at most 2147483647"
        );
        assert!(NEEDS.check_with((1 << 31) - 1, || None).is_ok());
    }

    #[test]
    fn a_build_larger_than_the_available_memory_is_refused() {
        // Ten million triangles need about 1.2 GiB at 128 bytes each.
        let error = NEEDS
            .check_with(10_000_000, || Some(512 << 20))
            .unwrap_err();
        assert_eq!(
            error.to_string(),
            "10000000 triangles: building the test tree needs about 1220 MiB, \
             and only 512 MiB of memory is available"
        );
        assert!(NEEDS.check_with(10_000_000, || Some(64 << 30)).is_ok());
        // Unknown memory is not an error.
        assert!(NEEDS.check_with(10_000_000, || None).is_ok());
        // Small builds do not ask.
        assert!(
            NEEDS
                .check_with(1000, || panic!("asked for a small build"))
                .is_ok()
        );
    }

    #[test]
    fn this_machine_reports_its_memory() {
        if cfg!(target_os = "linux") {
            let available = available_memory().expect("MemAvailable in /proc/meminfo");
            assert!(available > 16 << 20, "{available} bytes");
        }
    }
}

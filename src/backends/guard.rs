//! A third-party crate's panic while building, turned into an error: some
//! crates index out of bounds or unwrap a `None` on vertices they cannot
//! handle (non-finite or huge coordinates), and a bad mesh must give a
//! clear error, never a panic.

use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `build`, crate `name`'s build over one mesh; a panic inside it
/// becomes an error naming the crate and quoting its message.
pub(super) fn build_or_error<T>(name: &str, build: impl FnOnce() -> T) -> anyhow::Result<T> {
    catch_unwind(AssertUnwindSafe(build)).map_err(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".to_string());
        anyhow::anyhow!("{name} panicked while building over this mesh: {message}")
    })
}

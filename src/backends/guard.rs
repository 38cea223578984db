//! A third-party crate's panic while building, turned into an error: some
//! crates index out of bounds or unwrap a `None` on vertices they cannot
//! handle (non-finite or huge coordinates), and a bad mesh must give a
//! clear error, never a panic. While such a build runs, the panic hook
//! stays quiet about panics raised in code outside this workspace (the
//! error carries the message), so a caught panic does not print a
//! backtrace that reads like a crash.

use std::panic::{AssertUnwindSafe, PanicHookInfo, catch_unwind};
use std::sync::Once;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How many guarded builds are running, on any thread.
static GUARDED_BUILDS: AtomicUsize = AtomicUsize::new(0);

/// Runs `build`, crate `name`'s build over one mesh; a panic inside it
/// becomes an error naming the crate and quoting its message.
pub(super) fn build_or_error<T>(name: &str, build: impl FnOnce() -> T) -> anyhow::Result<T> {
    install_quiet_hook();
    GUARDED_BUILDS.fetch_add(1, Ordering::SeqCst);
    let result = catch_unwind(AssertUnwindSafe(build));
    GUARDED_BUILDS.fetch_sub(1, Ordering::SeqCst);
    result.map_err(|panic| {
        let message = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".to_string());
        anyhow::anyhow!("{name} panicked while building over this mesh: {message}")
    })
}

/// Wraps the panic hook in place once: panics raised outside this
/// workspace while a guarded build runs are not printed, every other
/// panic goes to the previous hook as before. A crate build may panic on
/// one of its own worker threads, so the test is the panic's source
/// file, not the thread it runs on.
fn install_quiet_hook() {
    static INSTALL: Once = Once::new();
    INSTALL.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if GUARDED_BUILDS.load(Ordering::SeqCst) > 0 && raised_outside_workspace(info) {
                return;
            }
            previous(info)
        }));
    });
}

/// Whether a panic was raised in a dependency's source: the compiler
/// records workspace files by relative path and registry or vendored
/// crates by absolute path.
fn raised_outside_workspace(info: &PanicHookInfo) -> bool {
    info.location()
        .is_some_and(|at| std::path::Path::new(at.file()).is_absolute())
}

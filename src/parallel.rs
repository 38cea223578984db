//! The worker threads every parallel pass runs on.
//!
//! Each worker sets flush-to-zero and denormals-are-zero before its first
//! job, as Embree asks of every thread that calls it; our tracer runs in the
//! same floating-point mode so the two are compared like for like. Work is
//! split so that every result depends only on its own index, never on which
//! thread computed it: images are bit-identical for any thread count.

use rayon::{ThreadPool, ThreadPoolBuilder};

/// A pool of `threads` workers (all cores when `None`), each in FTZ/DAZ mode.
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<ThreadPool> {
    raycheck_reference::enable_flush_to_zero_and_denormals_are_zero();
    let pool = ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .start_handler(|_| raycheck_reference::enable_flush_to_zero_and_denormals_are_zero())
        .build()?;
    Ok(pool)
}

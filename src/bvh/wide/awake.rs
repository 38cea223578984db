//! Keeping rayon's other workers awake through a short build.
//!
//! A rayon worker that finds no work spins briefly, then sleeps until new
//! work wakes it. A build alternates parallel passes with sequential steps
//! (the root's splits, the layout) longer than that spin, so each
//! parallel pass began while the other worker was still waking: on the
//! 2-core Xeon VM a woken worker took 10-120 us to start, against about
//! 500 us for the monkey's whole two-thread build. Waiting beside the
//! build, stealing its work as it appears, the worker meets every pass
//! awake: in `perf` the monkey's two-thread build took 482-484 us
//! (median of 36 builds, two runs) against 511-532 us. This is the
//! spin-then-steal wait of Embree's and TBB's task schedulers, kept to one
//! build.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// How long a worker waits beside a build at most. The waits matter only
/// to builds of a few milliseconds; the bound keeps a wait that another
/// build's work ran into (a worker stealing while it waits may pick up
/// another build's waiting helper) from holding that work up for long.
const LONGEST_WAIT: Duration = Duration::from_millis(2);

/// Runs `build` on this worker while another worker of the pool waits
/// beside it, running whatever parallel work the build leaves to steal,
/// until the build returns or [`LONGEST_WAIT`] passes. On a pool of one
/// thread `build` just runs.
pub(super) fn with_helper_awake<T: Send>(build: impl FnOnce() -> T + Send) -> T {
    if rayon::current_num_threads() < 2 {
        return build();
    }
    let done = AtomicBool::new(false);
    let (value, ()) = rayon::join(
        || {
            let value = build();
            done.store(true, Ordering::Release);
            value
        },
        || help_until(&done),
    );
    value
}

/// Steals work until `done` is set or [`LONGEST_WAIT`] has passed.
fn help_until(done: &AtomicBool) {
    let started = Instant::now();
    while !done.load(Ordering::Acquire) && started.elapsed() < LONGEST_WAIT {
        if rayon::yield_now() != Some(rayon::Yield::Executed) {
            std::hint::spin_loop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;

    /// On one thread and on several, the build's parallel work all runs
    /// and its value comes back, whether it finishes within the wait or
    /// outlasts it.
    #[test]
    fn the_build_runs_whole_and_returns_its_value() {
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            for pause in [Duration::ZERO, 2 * LONGEST_WAIT] {
                let sum = pool.install(|| {
                    with_helper_awake(|| {
                        std::thread::sleep(pause);
                        (0..10_000u64).into_par_iter().sum::<u64>()
                    })
                });
                assert_eq!(sum, 10_000 * 9_999 / 2, "{threads} threads, {pause:?}");
            }
        }
    }
}

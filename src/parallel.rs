//! The worker threads every parallel pass runs on, and the Embree device
//! with as many threads.
//!
//! A run's [`InstructionSets`] say which kernel our wide BVH traverses
//! with and how wide Embree's kernels may go (its device's `isa=`), so
//! the two can be timed at the same width as well as each at its best.
//!
//! Each worker sets flush-to-zero and denormals-are-zero before its first
//! job, as Embree asks of every thread that calls it; our tracer runs in the
//! same floating-point mode so the two are compared like for like. Work is
//! split so that every result depends only on its own index, never on which
//! thread computed it: images are bit-identical for any thread count.

use crate::backends::BuildContext;
use crate::bvh::wide::Kernel;
use raycheck_reference::{Device, DeviceConfig, Isa};
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::sync::OnceLock;

/// A pool of `threads` workers (all cores when `None`), each in FTZ/DAZ mode.
pub fn thread_pool(threads: Option<usize>) -> anyhow::Result<ThreadPool> {
    raycheck_reference::enable_flush_to_zero_and_denormals_are_zero();
    let pool = ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .start_handler(|_| raycheck_reference::enable_flush_to_zero_and_denormals_are_zero())
        .build()?;
    Ok(pool)
}

/// The instruction sets a run's tracers use: the kernel our wide BVH
/// traverses with, and the widest Embree may select.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InstructionSets {
    pub kernel: Kernel,
    pub embree: Isa,
}

impl Default for InstructionSets {
    /// Each side at its widest on this CPU.
    fn default() -> Self {
        Self {
            kernel: Kernel::detect(),
            embree: Isa::Auto,
        }
    }
}

/// One thread count's workers: the pool, and the Embree device whose
/// builds use as many threads, so ours and Embree's run on the same count.
///
/// The device is made when first asked for. Embree builds with the largest
/// `threads=` of all its live devices (`rtcNewDevice`: its task scheduler
/// is one per process), so a one-thread device builds on every core while
/// a device of every core lives; `perf` therefore measures its thread
/// counts in ascending order and makes each count's device only then.
pub struct Workers {
    pool: ThreadPool,
    config: DeviceConfig,
    device: OnceLock<Device>,
    kernel: Kernel,
}

impl Workers {
    /// `threads` workers (all cores when `None`), their Embree device
    /// limited to `sets.embree`, and our kernel. Embree is asked for such
    /// a device here once (and it is let go), so that a configuration it
    /// refuses is an error now rather than when the device is first used.
    pub fn new(threads: Option<usize>, sets: InstructionSets) -> anyhow::Result<Self> {
        let pool = thread_pool(threads)?;
        let config = DeviceConfig {
            threads: Some(pool.current_num_threads()),
            verbose: 0,
            isa: sets.embree,
        };
        drop(Device::new(&config)?);
        Ok(Self {
            pool,
            config,
            device: OnceLock::new(),
            kernel: sets.kernel,
        })
    }

    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    pub fn pool(&self) -> &ThreadPool {
        &self.pool
    }

    /// The Embree device, made on first use.
    pub fn device(&self) -> &Device {
        self.device.get_or_init(|| {
            Device::new(&self.config).unwrap_or_else(|error| {
                panic!(
                    "Embree refused a device configuration it accepted when the run began: {error}"
                )
            })
        })
    }

    /// Runs `work` on these workers.
    pub fn install<R: Send>(&self, work: impl FnOnce() -> R + Send) -> R {
        self.pool.install(work)
    }

    /// What backends built for these workers use.
    pub fn build_context(&self) -> BuildContext<'_> {
        BuildContext {
            device: self.device(),
            kernel: self.kernel,
        }
    }
}

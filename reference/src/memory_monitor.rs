//! Counts the bytes a device holds, through Embree's memory monitor callback
//! (`rtcSetDeviceMemoryMonitorFunction` in Embree's API docs: `bytes` > 0 on
//! allocation, < 0 on release, possibly from several threads at once).

use std::ffi::c_void;
use std::sync::Mutex;
use std::sync::atomic::{AtomicIsize, Ordering};

use crate::ffi;

/// The device's live byte count, and a lock that lets one scene build at a
/// time read the count's change as its own.
#[derive(Default)]
pub(crate) struct MemoryMonitor {
    live_bytes: AtomicIsize,
    build_lock: Mutex<()>,
}

impl MemoryMonitor {
    /// Registers the callback on `device`. `self` must stay at this address
    /// until the device is released (it lives inside an `Arc`).
    pub(crate) fn install(&self, device: ffi::RtcDevice) {
        let user = (&self.live_bytes as *const AtomicIsize)
            .cast_mut()
            .cast::<c_void>();
        // SAFETY: `user` points to an atomic that outlives the device.
        unsafe { ffi::rtcSetDeviceMemoryMonitorFunction(device, Some(on_memory_change), user) };
    }

    /// Runs `build` alone among this device's builds and returns its result
    /// with the net bytes the device gained meanwhile.
    pub(crate) fn measure<T>(&self, build: impl FnOnce() -> T) -> (T, usize) {
        let _only_build = self.build_lock.lock().unwrap_or_else(|e| e.into_inner());
        let before = self.live_bytes.load(Ordering::SeqCst);
        let result = build();
        let after = self.live_bytes.load(Ordering::SeqCst);
        (result, usize::try_from(after - before).unwrap_or(0))
    }
}

/// Accumulates every change and never cancels the allocation.
unsafe extern "C" fn on_memory_change(user: *mut c_void, bytes: isize, _post: bool) -> bool {
    // SAFETY: `user` is the atomic registered in `install`, still alive.
    let live_bytes = unsafe { &*user.cast::<AtomicIsize>() };
    live_bytes.fetch_add(bytes, Ordering::Relaxed);
    true
}

//! A hold on oneTBB's thread limit over a phase that runs on fewer threads
//! than the machine has.
//!
//! Embree's TBB task scheduler turns a device's `threads=N` into a
//! `tbb::global_control` of `max_allowed_parallelism`, and deletes and
//! makes that control again whenever a device is made or released
//! (`TaskScheduler::create` in Embree's `taskschedulertbb.cpp`). Between
//! the two the limit is every core; oneTBB 2021.11 and later (the Embree
//! 4.4 wheel bundles 2021.12) then leave a worker admitted while it was
//! lifted spinning in `sched_yield` for as long as the lower limit stays
//! (oneTBB issue #1417, "tbb::global_control does not stop spinning
//! threads"): a core kept busy beside a one-thread measurement, and on a
//! machine with SMT, half of the measured core. oneTBB obeys the lowest of
//! all live controls, so one of our own, held over the phase, keeps the
//! limit from lifting.
//!
//! The control is made through oneTBB's exported entry points
//! (`tbb::detail::r1::create` and `destroy` of a `d1::global_control`, the
//! functions the C++ class's constructor and destructor call), looked up
//! in the process: an Embree built with its own task scheduler brings no
//! oneTBB, and then there is nothing to hold.

use std::ffi::{CStr, c_void};

/// `tbb::detail::d1::global_control`'s layout in oneTBB 2021: the value,
/// a reserved word and the parameter.
#[repr(C)]
struct GlobalControl {
    value: usize,
    reserved: isize,
    parameter: i32,
}

/// `global_control::max_allowed_parallelism`.
const MAX_ALLOWED_PARALLELISM: i32 = 0;

type Entry = unsafe extern "C" fn(*mut GlobalControl);

const CREATE: &CStr = c"_ZN3tbb6detail2r16createERNS0_2d114global_controlE";
const DESTROY: &CStr = c"_ZN3tbb6detail2r17destroyERNS0_2d114global_controlE";

/// oneTBB held to at most `threads` threads until dropped.
pub struct ThreadLimit {
    /// Registered with oneTBB by address, so boxed: it must not move.
    control: Box<GlobalControl>,
    destroy: Entry,
}

// SAFETY: oneTBB registers and unregisters controls under its own lock,
// from any thread.
unsafe impl Send for ThreadLimit {}
unsafe impl Sync for ThreadLimit {}

impl ThreadLimit {
    /// Holds oneTBB to at most `threads` (at least 1) threads; `None` when
    /// the process has no oneTBB.
    pub fn hold(threads: usize) -> Option<Self> {
        let (create, destroy) = (entry(CREATE)?, entry(DESTROY)?);
        let mut control = Box::new(GlobalControl {
            value: threads.max(1),
            reserved: 0,
            parameter: MAX_ALLOWED_PARALLELISM,
        });
        // SAFETY: `create` is oneTBB's registration of a control of this
        // layout; the box keeps it at one address until `drop` removes it.
        unsafe { create(&mut *control) };
        Some(Self { control, destroy })
    }
}

impl Drop for ThreadLimit {
    fn drop(&mut self) {
        // SAFETY: the control was registered by `hold` and is removed once.
        unsafe { (self.destroy)(&mut *self.control) };
    }
}

/// oneTBB's function `name`, if a library of the process exports it.
fn entry(name: &CStr) -> Option<Entry> {
    // SAFETY: a lookup by name in the libraries already loaded.
    let address: *mut c_void = unsafe { libc::dlsym(libc::RTLD_DEFAULT, name.as_ptr()) };
    // SAFETY: both names are functions taking a `global_control&`.
    (!address.is_null()).then(|| unsafe { std::mem::transmute::<*mut c_void, Entry>(address) })
}

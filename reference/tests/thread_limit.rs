//! oneTBB's workers stay asleep under a held thread limit while Embree
//! devices come and go; alone in its binary, so no other test's threads
//! count in the process's CPU time.

use raycheck_reference::{Device, DeviceConfig, SceneOptions, ThreadLimit, TriangleMeshRef};
use std::time::Duration;

/// CPU time of the whole process so far, in seconds.
fn process_cpu_seconds() -> f64 {
    // SAFETY: `getrusage` fills the struct it is given.
    let usage = unsafe {
        let mut usage: libc::rusage = std::mem::zeroed();
        libc::getrusage(libc::RUSAGE_SELF, &mut usage);
        usage
    };
    let seconds = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    seconds(usage.ru_utime) + seconds(usage.ru_stime)
}

/// A one-thread device made after another was built on and released (as
/// a run over several thread counts makes them) leaves oneTBB's workers
/// asleep while the limit is held: half a second of idling costs no CPU.
/// Without the hold, oneTBB 2021.12 spends that half second spinning on
/// every other core.
#[test]
fn a_held_limit_leaves_no_worker_spinning_after_devices_come_and_go() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    if cores < 2 {
        eprintln!("skipped: one core leaves oneTBB no worker to spin");
        return;
    }
    let limit = ThreadLimit::hold(1).expect(
        "the bundled Embree brings oneTBB (an Embree built with its own tasking would not)",
    );
    // Large enough for Embree to build in parallel tasks.
    const TRIANGLES: u32 = 40_000;
    let positions: Vec<[f32; 3]> = (0..3 * TRIANGLES)
        .map(|i| {
            let (t, corner) = ((i / 3) as f32, i % 3);
            let (x, y) = (t % 200.0, (t / 200.0).floor());
            match corner {
                0 => [x, y, 0.0],
                1 => [x + 1.0, y, 0.0],
                _ => [x, y + 1.0, 0.1],
            }
        })
        .collect();
    let indices: Vec<[u32; 3]> = (0..TRIANGLES)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let mesh = [TriangleMeshRef {
        positions: &positions,
        indices: &indices,
    }];
    let config = DeviceConfig {
        threads: Some(1),
        ..DeviceConfig::default()
    };
    let first = Device::new(&config).unwrap();
    drop(first.build_scene(&mesh, SceneOptions::default()).unwrap());
    drop(first);
    // The spinning lasts while a one-thread device lives.
    let second = Device::new(&config).unwrap();
    let scene = second.build_scene(&mesh, SceneOptions::default()).unwrap();
    let before = process_cpu_seconds();
    std::thread::sleep(Duration::from_millis(500));
    let idle = process_cpu_seconds() - before;
    drop((scene, second, limit));
    assert!(idle < 0.1, "{idle:.2} s of CPU in 0.5 s of idling");
}

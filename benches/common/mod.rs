//! What the three benchmark suites share: the scenes, a quick mode for
//! `cargo bench -- --test`, and the Embree device.

use raycheck_reference::{Device, DeviceConfig};

/// Whether criterion runs each benchmark once as a smoke test.
pub fn test_mode() -> bool {
    std::env::args().any(|a| a == "--test")
}

/// Every scene, smallest first; the two smallest under `--test`.
pub fn scenes() -> Vec<raycheck::scene::Scene> {
    let names: &[&str] = if test_mode() {
        &["cornell", "monkey"]
    } else {
        &raycheck::scene::BENCHMARK_SCENES
    };
    names
        .iter()
        .map(|name| raycheck::scene::load(name).expect("a built-in scene"))
        .collect()
}

/// A rayon pool on every core (FTZ/DAZ, as Embree asks) and an Embree
/// device on as many threads.
pub fn pool_and_device() -> (rayon::ThreadPool, Device) {
    let pool = raycheck::parallel::thread_pool(None).expect("a thread pool");
    let device = Device::new(&DeviceConfig {
        threads: Some(pool.current_num_threads()),
        ..DeviceConfig::default()
    })
    .expect("an Embree device");
    (pool, device)
}

//! What the three benchmark suites share: the scenes, a quick mode for
//! `cargo bench -- --test`, and the workers with their Embree device.

use raycheck::parallel::{InstructionSets, Workers};

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

/// Workers on every core (FTZ/DAZ, as Embree asks) and an Embree device
/// on as many threads.
pub fn workers() -> Workers {
    Workers::new(None, InstructionSets::default()).expect("workers and an Embree device")
}

//! The scenes every measurement (the report, `raycheck perf`, the benches)
//! runs over, smallest to largest, and the short list of their quick runs.

/// The Cornell box, Suzanne and the Stanford dragon at its four resolutions.
pub const BENCHMARK_SCENES: [&str; 6] = [
    "cornell",
    "monkey",
    "dragon-11k",
    "dragon-48k",
    "dragon-203k",
    "dragon-871k",
];

/// The scale test: the dragon subdivided to 13.9M triangles, timed by
/// `raycheck perf` (not `--quick`) on ours and Embree, for how build time,
/// memory and time per ray grow beyond the packaged meshes.
pub const SCALE_SCENES: [&str; 1] = ["dragon-14m"];

/// The scenes of a `--quick` run.
pub const QUICK_SCENES: [&str; 3] = ["cornell", "monkey", "dragon-11k"];

/// [`QUICK_SCENES`] when `quick`, else [`BENCHMARK_SCENES`].
pub fn benchmark_scenes(quick: bool) -> &'static [&'static str] {
    if quick {
        &QUICK_SCENES
    } else {
        &BENCHMARK_SCENES
    }
}

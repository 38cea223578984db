//! Saved runs made up for tests: the comparison with a baseline and the
//! report's history read numbers, never time anything.

use super::PerfReport;
use super::measure::{PerfRow, Stat};
use crate::results::RunMeta;

/// A row of `backend` on `scene` whose every run is `scale` times
/// `jitter` (build 5 ms, primary 10, shadow 20, diffuse 4 Mrays/s).
pub fn row(scene: &str, backend: &str, scale: f64, jitter: &[f64]) -> PerfRow {
    let stat = |base: f64| Stat::of(jitter.iter().map(|j| base * scale * j).collect());
    PerfRow {
        scene: scene.into(),
        triangles: 10,
        threads: 1,
        backend: backend.into(),
        primary_rays: 1,
        shadow_rays: 1,
        diffuse_rays: 1,
        build_ms: Stat::of(jitter.iter().map(|j| 5.0 * j).collect()),
        builds_per_run: 1,
        mrays_primary: stat(10.0),
        mrays_shadow: stat(20.0),
        mrays_diffuse: stat(4.0),
        peak_build_mib: None,
        bytes_per_tri: Some(50.0),
    }
}

/// A run of `rows`, saved on `date` at `commit`.
pub fn report(rows: Vec<PerfRow>, date: &str, commit: &str) -> PerfReport {
    PerfReport {
        meta: RunMeta {
            machine: "m".into(),
            date: date.into(),
            commit: commit.into(),
            threads: 1,
            load_average: None,
        },
        kernel: "k".into(),
        embree_isa: "e".into(),
        embree_binding: raycheck_reference::BINDING_REVISION,
        resolution: 8,
        runs: 7,
        backends: vec!["ours".into()],
        rows,
        scaling: Vec::new(),
    }
}

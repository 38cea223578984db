//! Set-up the integration tests share: Embree as the report checks against
//! it (MEDIUM, ROBUST), and compare runs over lists of backends.

use raycheck::backends::{Backend, BackendName, EMBREE_ROBUST};
use raycheck::check;
use raycheck::geometry::TriangleMesh;
use raycheck::parallel::thread_pool;
use raycheck::results::{CompareSummary, compare_scene};
use raycheck::scene::Scene;
use raycheck_reference::{Device, DeviceConfig};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

pub fn embree_device(threads: usize) -> Device {
    Device::new(&DeviceConfig {
        threads: Some(threads),
        ..DeviceConfig::default()
    })
    .unwrap()
}

/// `mesh` in Embree with the reference options, on `device`.
pub fn reference_scene(device: &Device, mesh: &TriangleMesh) -> raycheck_reference::Scene {
    raycheck::backends::embree::build_scene(device, mesh, EMBREE_ROBUST).unwrap()
}

/// The compare ray sets of the scene `name` at `resolution`² through the
/// backends `names`, on every core.
pub fn compare(name: &str, names: &str, resolution: u32) -> CompareSummary {
    let scene = raycheck::scene::load(name).unwrap();
    let names = BackendName::parse_list(names).unwrap();
    let pool = thread_pool(None).unwrap();
    let device = embree_device(pool.current_num_threads());
    pool.install(|| compare_scene(&scene, &names, &device, resolution))
        .unwrap()
}

/// The same through backends built by the test.
pub fn compare_with(scene: &Scene, backends: &[&dyn Backend], resolution: u32) -> CompareSummary {
    let pool = thread_pool(None).unwrap();
    pool.install(|| {
        CompareSummary::new(
            scene,
            resolution,
            check::compare(scene, backends, resolution),
        )
    })
}

/// The folder of one quick report, written once for every test that reads
/// it (kept for the life of the test process).
pub fn quick_report() -> &'static Path {
    static REPORT: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, out) = REPORT.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("report");
        raycheck::report::write_report(&raycheck::report::ReportOptions {
            out: out.clone(),
            form: raycheck::report::Form::Quick,
            threads: None,
            history: None,
        })
        .unwrap();
        (dir, out)
    });
    out
}

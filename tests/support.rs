//! Set-up the integration tests share: Embree as the report checks against
//! it (MEDIUM, ROBUST), and compare runs over lists of backends.

use raycheck::backends::{Backend, BackendName};
use raycheck::check;
use raycheck::geometry::TriangleMesh;
use raycheck::parallel::{InstructionSets, Workers};
use raycheck::results::{CompareSummary, compare_scene};
use raycheck::run::{Form, RunContext, RunOptions};
use raycheck::scene::Scene;
use raycheck_reference::Device;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Workers on `threads` threads (every core when `None`) and their
/// Embree device.
pub fn workers(threads: Option<usize>) -> Workers {
    Workers::new(threads, InstructionSets::default()).unwrap()
}

/// A run on every core in `form`.
pub fn run(form: Form) -> RunContext {
    RunContext::new(RunOptions {
        threads: None,
        form,
        sets: InstructionSets::default(),
    })
    .unwrap()
}

/// `mesh` in Embree with the reference options (MEDIUM, ROBUST), on
/// `device`.
pub fn reference_scene(device: &Device, mesh: &TriangleMesh) -> raycheck_reference::Scene {
    raycheck::backends::embree::build_scene(device, mesh, raycheck::backends::embree::ROBUST)
        .unwrap()
}

/// The compare ray sets of the scene `name` at `resolution`² through the
/// backends `names`, on every core.
pub fn compare(name: &str, names: &str, resolution: u32) -> CompareSummary {
    let scene = raycheck::scene::load(name).unwrap();
    let names = BackendName::parse_list(names).unwrap();
    compare_scene(&scene, &names, &workers(None), resolution).unwrap()
}

/// The same through backends built by the test.
pub fn compare_with(scene: &Scene, backends: &[&dyn Backend], resolution: u32) -> CompareSummary {
    workers(None).install(|| {
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
        let options = raycheck::report::ReportOptions {
            out: out.clone(),
            history: None,
        };
        raycheck::report::write_report(&run(Form::Quick), &options).unwrap();
        (dir, out)
    });
    out
}

//! Set-up the integration tests share: Embree as the report checks against
//! it (MEDIUM, ROBUST), on a given number of threads.

use raycheck::geometry::TriangleMesh;
use raycheck::report::measure::REFERENCE_OPTIONS;
use raycheck_reference::{Device, DeviceConfig, Scene};

pub fn embree_device(threads: usize) -> Device {
    Device::new(&DeviceConfig {
        threads: Some(threads),
        verbose: 0,
    })
    .unwrap()
}

/// `mesh` in Embree with the reference options, on `device`.
pub fn reference_scene(device: &Device, mesh: &TriangleMesh) -> Scene {
    raycheck::backends::embree::build_scene(device, mesh, REFERENCE_OPTIONS).unwrap()
}

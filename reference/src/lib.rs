//! raycheck-reference: Intel Embree 4.4, wrapped for use as the reference
//! every raycheck hit is checked against.
//!
//! ```
//! use raycheck_reference::*;
//!
//! let device = Device::new(&DeviceConfig { threads: Some(2), ..DeviceConfig::default() })?;
//! let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
//! let indices = [[0, 1, 2]];
//! let mesh = TriangleMeshRef { positions: &positions, indices: &indices };
//! let scene = device.build_scene(&[mesh], SceneOptions::default())?;
//! enable_flush_to_zero_and_denormals_are_zero();
//! let ray = RayQuery { origin: [0.25, 0.25, 1.0], dir: [0.0, 0.0, -1.0], tnear: 0.0, tfar: f32::INFINITY };
//! let hit = scene.intersect(&ray).expect("the ray points at the triangle");
//! assert!((hit.t - 1.0).abs() < 1e-6);
//! # Ok::<(), EmbreeError>(())
//! ```
//!
//! The library comes from the build script (see `build.rs`): `EMBREE_DIR`,
//! or a per-user cache filled once from the pinned `embreex` wheel.
//! Dependents find its folder in `DEP_EMBREE4_ROOT`.
//!
//! The C declarations in `ffi` are written by hand for Embree 4.4 as built
//! with instance arrays (`RTCRayHit` is 96 bytes); a guard-word test proves
//! the library writes nothing past them.

mod bvh_statistics;
mod device;
mod error;
mod ffi;
mod float_mode;
mod isa;
mod memory_monitor;
mod mesh;
mod ray;
mod scene;
mod scene_options;
mod stdout_capture;
mod thread_limit;

#[cfg(test)]
mod layout_tests;

pub use bvh_statistics::{BvhStatistics, NodeGroupStatistics, bvh_statistics};
pub use device::{Device, DeviceConfig, DeviceProperty};
pub use error::{EmbreeError, RtcErrorCode};
pub use float_mode::{
    enable_flush_to_zero_and_denormals_are_zero, flush_to_zero_and_denormals_are_zero_enabled,
};
pub use isa::{Isa, SelectedIsa, UnknownIsa};
pub use mesh::TriangleMeshRef;
pub use ray::{BINDING_REVISION, EmbreeHit, RayQuery};
pub use scene::Scene;
pub use scene_options::{BuildQuality, SceneOptions};
pub use thread_limit::ThreadLimit;

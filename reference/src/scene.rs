//! A committed Embree scene and its two ray queries (`rtcNewScene`,
//! `rtcSetNewGeometryBuffer`, `rtcCommitScene`, `rtcIntersect1`,
//! `rtcOccluded1` in Embree's API docs).

use std::ptr;
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::device::{DeviceHandle, take_error};
use crate::ffi;
use crate::{EmbreeError, EmbreeHit, RayQuery, SceneOptions, TriangleMeshRef};

/// A committed, read-only scene. Queries may run from many threads at once;
/// each tracing thread should first call
/// [`crate::enable_flush_to_zero_and_denormals_are_zero`], as Embree asks.
///
/// Rays use mask `0xFFFFFFFF`, time 0 and flags 0, so every geometry is
/// visible.
pub struct Scene {
    raw: ffi::RtcScene,
    build_time: Duration,
    bytes: usize,
    triangle_count: usize,
    options: SceneOptions,
    // Declared last: released after the scene.
    device: Arc<DeviceHandle>,
}

// SAFETY: a committed scene is immutable and Embree documents
// `rtcIntersect1`/`rtcOccluded1` as thread-safe on it; the device it uses
// is kept alive by the `Arc`.
unsafe impl Send for Scene {}
// SAFETY: as above.
unsafe impl Sync for Scene {}

impl Drop for Scene {
    fn drop(&mut self) {
        if !self.raw.is_null() {
            // SAFETY: `raw` came from `rtcNewScene` and is released once.
            unsafe { ffi::rtcReleaseScene(self.raw) };
        }
    }
}

impl Scene {
    /// Copies the meshes into Embree-owned buffers (Embree pads vertex
    /// buffers it allocates for its 16-byte loads), commits, and reads the
    /// device error once afterwards.
    pub(crate) fn build(
        device: Arc<DeviceHandle>,
        meshes: &[TriangleMeshRef<'_>],
        options: SceneOptions,
    ) -> Result<Scene, EmbreeError> {
        for (index, mesh) in meshes.iter().enumerate() {
            mesh.check_indices(index)?;
        }
        // Clear an error a previous call on this thread may have left.
        let _ = take_error(device.raw, "an earlier call");
        let (built, bytes) = device
            .memory
            .measure(|| commit_new_scene(device.raw, meshes, options));
        let (raw, build_time) = built;
        let scene = Scene {
            raw,
            build_time,
            bytes,
            triangle_count: meshes.iter().map(|m| m.indices.len()).sum(),
            options,
            device,
        };
        take_error(scene.device.raw, "building a scene")?;
        Ok(scene)
    }

    /// The closest hit in `[tnear, tfar]`, or `None`.
    pub fn intersect(&self, query: &RayQuery) -> Option<EmbreeHit> {
        let mut ray_hit = ffi::RtcRayHit {
            ray: query.rtc_ray(),
            hit: ffi::RtcHit {
                geom_id: ffi::RTC_INVALID_GEOMETRY_ID,
                inst_id: [ffi::RTC_INVALID_GEOMETRY_ID],
                inst_prim_id: [ffi::RTC_INVALID_GEOMETRY_ID],
                ..ffi::RtcHit::default()
            },
        };
        // SAFETY: a committed scene, a valid `RTCRayHit`, default arguments.
        unsafe { ffi::rtcIntersect1(self.raw, &mut ray_hit, ptr::null_mut()) };
        EmbreeHit::read(&ray_hit)
    }

    /// Whether anything is hit in `[tnear, tfar]` (any hit, not the closest).
    pub fn occluded(&self, query: &RayQuery) -> bool {
        let mut ray = query.rtc_ray();
        // SAFETY: a committed scene, a valid `RTCRay`, default arguments.
        unsafe { ffi::rtcOccluded1(self.raw, &mut ray, ptr::null_mut()) };
        ray.tfar == f32::NEG_INFINITY
    }

    /// Wall time of `rtcCommitScene`, the BVH build.
    pub fn build_time(&self) -> Duration {
        self.build_time
    }

    /// Net bytes Embree's memory monitor saw the device gain while this
    /// scene was created and committed: the geometry buffer copies plus the
    /// BVH and its build-time leftovers.
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// The build quality and flags the scene was built with.
    pub fn options(&self) -> SceneOptions {
        self.options
    }

    /// Triangles handed in, over all meshes (Embree silently skips
    /// degenerate ones, such as those with NaN vertices).
    pub fn triangle_count(&self) -> usize {
        self.triangle_count
    }

    /// The raw handle, for this crate's layout tests.
    #[cfg(test)]
    pub(crate) fn raw(&self) -> ffi::RtcScene {
        self.raw
    }
}

/// Creates, fills and commits a scene; returns it with the commit's wall
/// time. Errors are left on the device for the caller to read once.
fn commit_new_scene(
    device: ffi::RtcDevice,
    meshes: &[TriangleMeshRef<'_>],
    options: SceneOptions,
) -> (ffi::RtcScene, Duration) {
    // SAFETY: every handle used below is live and comes from this device;
    // buffer pointers are written only within the item counts requested.
    unsafe {
        let scene = ffi::rtcNewScene(device);
        ffi::rtcSetSceneFlags(scene, options.raw_flags());
        ffi::rtcSetSceneBuildQuality(scene, options.quality.raw());
        for mesh in meshes {
            let geometry = ffi::rtcNewGeometry(device, ffi::RTC_GEOMETRY_TYPE_TRIANGLE);
            fill_buffer(
                geometry,
                ffi::RTC_BUFFER_TYPE_VERTEX,
                ffi::RTC_FORMAT_FLOAT3,
                mesh.positions,
            );
            fill_buffer(
                geometry,
                ffi::RTC_BUFFER_TYPE_INDEX,
                ffi::RTC_FORMAT_UINT3,
                mesh.indices,
            );
            ffi::rtcCommitGeometry(geometry);
            ffi::rtcAttachGeometry(scene, geometry);
            ffi::rtcReleaseGeometry(geometry);
        }
        let start = Instant::now();
        ffi::rtcCommitScene(scene);
        (scene, start.elapsed())
    }
}

/// Asks Embree for a new buffer of `items.len()` 12-byte items and copies
/// `items` into it. Embree returns NULL for zero items, or on failure (with
/// the error left on the device).
///
/// # Safety
/// `geometry` must be a live triangle geometry.
unsafe fn fill_buffer<T: Copy>(geometry: ffi::RtcGeometry, kind: i32, format: i32, items: &[T]) {
    const { assert!(size_of::<T>() == 12) };
    // SAFETY: the caller passes a live geometry.
    let buffer =
        unsafe { ffi::rtcSetNewGeometryBuffer(geometry, kind, 0, format, 12, items.len()) };
    if !buffer.is_null() {
        // SAFETY: Embree allocated at least `items.len() * 12` bytes there.
        unsafe { ptr::copy_nonoverlapping(items.as_ptr(), buffer.cast::<T>(), items.len()) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Device, DeviceConfig};

    /// Why `build` checks indices itself: handed straight to Embree, a
    /// triangle with an out-of-range index is dropped at commit and no error
    /// is reported.
    #[test]
    fn embree_alone_drops_a_bad_triangle_without_an_error() {
        let device = Device::new(&DeviceConfig::default()).unwrap();
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let indices = [[0, 1, 2], [0, 1, 7]];
        let mesh = TriangleMeshRef {
            positions: &positions,
            indices: &indices,
        };
        let handle = &device.handle_for_tests();
        let (raw, _) = commit_new_scene(handle.raw, &[mesh], SceneOptions::default());
        let error = take_error(handle.raw, "building a scene");
        let scene = Scene {
            raw,
            build_time: Duration::ZERO,
            bytes: 0,
            triangle_count: 2,
            options: SceneOptions::default(),
            device: Arc::clone(handle),
        };
        assert!(error.is_ok(), "{error:?}");
        let ray = RayQuery {
            origin: [0.25, 0.25, 1.0],
            dir: [0.0, 0.0, -1.0],
            tnear: 0.0,
            tfar: f32::INFINITY,
        };
        assert_eq!(scene.intersect(&ray).map(|hit| hit.prim_id), Some(0));
    }
}

//! The few Embree 4 C API calls and types this crate uses, declared by hand.
//!
//! Layouts follow `include/embree4/rtcore_ray.h`, `rtcore_scene.h`,
//! `rtcore_device.h`, `rtcore_geometry.h`, `rtcore_buffer.h` and
//! `rtcore_common.h` of Embree 4.4.0 **as built with instance arrays on and
//! `RTC_MAX_INSTANCE_LEVEL_COUNT = 1`** (the library this crate links):
//! `RTCHit` then ends with `instID[1]` and `instPrimID[1]`, so `RTCRayHit` is
//! 96 bytes. The assertions at the bottom and the guard-word test keep that
//! honest.

use std::ffi::{c_char, c_uint, c_void};

/// Opaque `RTCDevice`.
pub type RtcDevice = *mut c_void;
/// Opaque `RTCScene`.
pub type RtcScene = *mut c_void;
/// Opaque `RTCGeometry`.
pub type RtcGeometry = *mut c_void;

/// `RTCMemoryMonitorFunction` (`rtcSetDeviceMemoryMonitorFunction`).
pub type RtcMemoryMonitorFunction =
    unsafe extern "C" fn(user: *mut c_void, bytes: isize, post: bool) -> bool;

/// `RTC_INVALID_GEOMETRY_ID`: the `geomID` of a miss.
pub const RTC_INVALID_GEOMETRY_ID: c_uint = u32::MAX;

/// `enum RTCSceneFlags`: `RTC_SCENE_FLAG_ROBUST`.
pub const RTC_SCENE_FLAG_ROBUST: i32 = 1 << 2;
/// `enum RTCGeometryType`: `RTC_GEOMETRY_TYPE_TRIANGLE`.
pub const RTC_GEOMETRY_TYPE_TRIANGLE: i32 = 0;
/// `enum RTCBufferType`: `RTC_BUFFER_TYPE_INDEX`.
pub const RTC_BUFFER_TYPE_INDEX: i32 = 0;
/// `enum RTCBufferType`: `RTC_BUFFER_TYPE_VERTEX`.
pub const RTC_BUFFER_TYPE_VERTEX: i32 = 1;
/// `enum RTCFormat`: `RTC_FORMAT_UINT3`.
pub const RTC_FORMAT_UINT3: i32 = 0x5003;
/// `enum RTCFormat`: `RTC_FORMAT_FLOAT3`.
pub const RTC_FORMAT_FLOAT3: i32 = 0x9003;

/// `struct RTCRay` (16-byte aligned, 48 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RtcRay {
    pub org_x: f32,
    pub org_y: f32,
    pub org_z: f32,
    pub tnear: f32,
    pub dir_x: f32,
    pub dir_y: f32,
    pub dir_z: f32,
    pub time: f32,
    pub tfar: f32,
    pub mask: c_uint,
    pub id: c_uint,
    pub flags: c_uint,
}

/// `struct RTCHit` with one instance level and instance arrays
/// (16-byte aligned, 48 bytes).
#[repr(C, align(16))]
#[derive(Clone, Copy, Debug, Default)]
pub struct RtcHit {
    pub ng_x: f32,
    pub ng_y: f32,
    pub ng_z: f32,
    pub u: f32,
    pub v: f32,
    pub prim_id: c_uint,
    pub geom_id: c_uint,
    pub inst_id: [c_uint; 1],
    pub inst_prim_id: [c_uint; 1],
}

/// `struct RTCRayHit` (96 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct RtcRayHit {
    pub ray: RtcRay,
    pub hit: RtcHit,
}

const _: () = {
    assert!(size_of::<RtcRay>() == 48 && align_of::<RtcRay>() == 16);
    assert!(size_of::<RtcHit>() == 48 && align_of::<RtcHit>() == 16);
    assert!(size_of::<RtcRayHit>() == 96 && align_of::<RtcRayHit>() == 16);
    assert!(std::mem::offset_of!(RtcRayHit, hit) == 48);
    assert!(std::mem::offset_of!(RtcHit, inst_prim_id) == 32);
};

unsafe extern "C" {
    pub fn rtcNewDevice(config: *const c_char) -> RtcDevice;
    pub fn rtcReleaseDevice(device: RtcDevice);
    /// Takes `NULL` to read the error of a failed `rtcNewDevice`.
    pub fn rtcGetDeviceError(device: RtcDevice) -> i32;
    pub fn rtcGetDeviceLastErrorMessage(device: RtcDevice) -> *const c_char;
    pub fn rtcGetDeviceProperty(device: RtcDevice, property: i32) -> isize;
    pub fn rtcSetDeviceMemoryMonitorFunction(
        device: RtcDevice,
        monitor: Option<RtcMemoryMonitorFunction>,
        user: *mut c_void,
    );

    pub fn rtcNewScene(device: RtcDevice) -> RtcScene;
    pub fn rtcSetSceneFlags(scene: RtcScene, flags: i32);
    pub fn rtcSetSceneBuildQuality(scene: RtcScene, quality: i32);
    pub fn rtcAttachGeometry(scene: RtcScene, geometry: RtcGeometry) -> c_uint;
    pub fn rtcCommitScene(scene: RtcScene);
    pub fn rtcReleaseScene(scene: RtcScene);

    pub fn rtcNewGeometry(device: RtcDevice, kind: i32) -> RtcGeometry;
    pub fn rtcSetNewGeometryBuffer(
        geometry: RtcGeometry,
        kind: i32,
        slot: c_uint,
        format: i32,
        byte_stride: usize,
        item_count: usize,
    ) -> *mut c_void;
    pub fn rtcCommitGeometry(geometry: RtcGeometry);
    pub fn rtcReleaseGeometry(geometry: RtcGeometry);

    /// `args` is the optional `RTCIntersectArguments*`; `NULL` means defaults.
    pub fn rtcIntersect1(scene: RtcScene, rayhit: *mut RtcRayHit, args: *mut c_void);
    /// `args` is the optional `RTCOccludedArguments*`; `NULL` means defaults.
    /// On occlusion Embree sets `ray.tfar` to `-inf`.
    pub fn rtcOccluded1(scene: RtcScene, ray: *mut RtcRay, args: *mut c_void);
}

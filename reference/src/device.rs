//! An Embree device (`rtcNewDevice`, `rtcGetDeviceProperty`,
//! `rtcGetDeviceError` in Embree's API docs) and the scenes it builds.

use std::ffi::{CStr, CString};
use std::ptr;
use std::sync::Arc;

use crate::error::RtcErrorCode;
use crate::ffi;
use crate::isa::{Isa, SelectedIsa, parse_selection};
use crate::memory_monitor::MemoryMonitor;
use crate::stdout_capture::capture_stdout;
use crate::{EmbreeError, Scene, SceneOptions, TriangleMeshRef};

/// What `rtcNewDevice` is told.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DeviceConfig {
    /// `threads=N`; `None` lets Embree use every core.
    pub threads: Option<usize>,
    /// `verbose=N`: 0 is silent, higher levels print to standard output.
    pub verbose: u32,
    /// `isa=`: the instruction set Embree's kernels may use at most.
    pub isa: Isa,
}

impl DeviceConfig {
    /// Embree's comma-separated `key=value` configuration string.
    pub(crate) fn config_string(&self) -> String {
        let mut config = format!("verbose={}", self.verbose);
        if let Some(threads) = self.threads {
            config.push_str(&format!(",threads={threads}"));
        }
        if let Some(isa) = self.isa.config_value() {
            config.push_str(&format!(",isa={isa}"));
        }
        config
    }
}

/// `RTCDeviceProperty` values worth asking about (Embree's
/// `rtcGetDeviceProperty` documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DeviceProperty {
    /// `major * 10000 + minor * 100 + patch`, e.g. 40400.
    Version,
    VersionMajor,
    VersionMinor,
    VersionPatch,
    NativeRay4Supported,
    NativeRay8Supported,
    NativeRay16Supported,
    RayMaskSupported,
    BackfaceCullingEnabled,
    FilterFunctionSupported,
    IgnoreInvalidRaysEnabled,
    CompactPolysEnabled,
    TriangleGeometrySupported,
    /// 0 internal, 1 TBB, 2 PPL.
    TaskingSystem,
}

impl DeviceProperty {
    fn raw(self) -> i32 {
        match self {
            Self::Version => 0,
            Self::VersionMajor => 1,
            Self::VersionMinor => 2,
            Self::VersionPatch => 3,
            Self::NativeRay4Supported => 32,
            Self::NativeRay8Supported => 33,
            Self::NativeRay16Supported => 34,
            Self::RayMaskSupported => 64,
            Self::BackfaceCullingEnabled => 65,
            Self::FilterFunctionSupported => 66,
            Self::IgnoreInvalidRaysEnabled => 67,
            Self::CompactPolysEnabled => 68,
            Self::TriangleGeometrySupported => 96,
            Self::TaskingSystem => 128,
        }
    }
}

/// An Embree device. Cheap to share: scenes keep it alive.
#[derive(Clone)]
pub struct Device {
    handle: Arc<DeviceHandle>,
    /// The `isa=` it was created with.
    isa: Isa,
}

/// Owns the raw device; released when the last [`Device`] or [`Scene`] goes.
pub(crate) struct DeviceHandle {
    pub(crate) raw: ffi::RtcDevice,
    pub(crate) memory: MemoryMonitor,
}

// SAFETY: Embree's device API is thread-safe (Embree API docs, "Thread
// safety"); the memory counter behind the monitor is atomic.
unsafe impl Send for DeviceHandle {}
// SAFETY: as above.
unsafe impl Sync for DeviceHandle {}

impl Drop for DeviceHandle {
    fn drop(&mut self) {
        // SAFETY: `raw` came from `rtcNewDevice` and is released once.
        unsafe { ffi::rtcReleaseDevice(self.raw) };
    }
}

impl Device {
    /// Creates a device; fails with Embree's own message when it refuses.
    pub fn new(config: &DeviceConfig) -> Result<Device, EmbreeError> {
        Self::from_config_string(config.config_string(), config.isa)
    }

    /// A device from a raw configuration string, whose `isa=` (if any)
    /// `isa` names.
    pub(crate) fn from_config_string(config: String, isa: Isa) -> Result<Device, EmbreeError> {
        let c_config = CString::new(config.clone()).map_err(|_| EmbreeError::DeviceCreation {
            config: config.clone(),
            code: RtcErrorCode::InvalidArgument,
            message: "the configuration string contains a NUL byte".into(),
        })?;
        // SAFETY: `c_config` is a NUL-terminated string that outlives the call.
        let raw = unsafe { ffi::rtcNewDevice(c_config.as_ptr()) };
        if raw.is_null() {
            // A failed creation leaves its error on the NULL device.
            let code = unsafe { ffi::rtcGetDeviceError(ptr::null_mut()) };
            return Err(EmbreeError::DeviceCreation {
                config,
                code: RtcErrorCode::from_raw(code).unwrap_or(RtcErrorCode::Unknown),
                message: last_error_message(ptr::null_mut()),
            });
        }
        let handle = Arc::new(DeviceHandle {
            raw,
            memory: MemoryMonitor::default(),
        });
        handle.memory.install(raw);
        Ok(Device { handle, isa })
    }

    /// The `isa=` this device was created with.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// The instruction set Embree selected for this device's ray queries,
    /// as Embree reports it: a device with the same `isa=` and `verbose=2`
    /// commits a one-triangle scene while standard output is captured
    /// (see the `isa` module), and its report is read.
    pub fn selected_isa(&self) -> Result<SelectedIsa, EmbreeError> {
        let probe = DeviceConfig {
            threads: Some(1),
            verbose: 2,
            isa: self.isa,
        };
        let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mesh = TriangleMeshRef {
            positions: &positions,
            indices: &[[0, 1, 2]],
        };
        let (built, output) = capture_stdout(|| {
            let device = Device::new(&probe)?;
            device
                .build_scene(&[mesh], SceneOptions::default())
                .map(drop)
        })?;
        built?;
        parse_selection(&output)
    }

    /// `RTC_DEVICE_PROPERTY_VERSION`: 40400 for Embree 4.4.0.
    pub fn version(&self) -> i64 {
        self.property(DeviceProperty::Version)
    }

    /// Reads one device property (`rtcGetDeviceProperty`).
    pub fn property(&self, property: DeviceProperty) -> i64 {
        // SAFETY: a live device and a property this Embree version defines.
        let value = unsafe { ffi::rtcGetDeviceProperty(self.handle.raw, property.raw()) };
        value as i64
    }

    /// Builds one scene with one triangle geometry per mesh (`geom_id` =
    /// the mesh's position in `meshes`). See [`Scene`].
    pub fn build_scene(
        &self,
        meshes: &[TriangleMeshRef<'_>],
        options: SceneOptions,
    ) -> Result<Scene, EmbreeError> {
        Scene::build(Arc::clone(&self.handle), meshes, options)
    }
}

#[cfg(test)]
impl Device {
    pub(crate) fn handle_for_tests(&self) -> Arc<DeviceHandle> {
        Arc::clone(&self.handle)
    }
}

/// Turns the device's pending error, if any, into an [`EmbreeError`]. Embree
/// keeps the first error of a thread until it is read, so one check after a
/// sequence of calls catches an error in any of them.
pub(crate) fn take_error(device: ffi::RtcDevice, during: &'static str) -> Result<(), EmbreeError> {
    // SAFETY: `device` is live; reading the error also clears it.
    let code = unsafe { ffi::rtcGetDeviceError(device) };
    match RtcErrorCode::from_raw(code) {
        None => Ok(()),
        Some(code) => Err(EmbreeError::Api {
            during,
            code,
            message: last_error_message(device),
        }),
    }
}

fn last_error_message(device: ffi::RtcDevice) -> String {
    // SAFETY: Embree returns NULL or a NUL-terminated string it owns.
    let message = unsafe { ffi::rtcGetDeviceLastErrorMessage(device) };
    if message.is_null() {
        String::new()
    } else {
        // SAFETY: non-NULL, NUL-terminated, valid until the next Embree call.
        unsafe { CStr::from_ptr(message) }
            .to_string_lossy()
            .into_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_config_string_names_only_what_is_set() {
        let default = DeviceConfig::default();
        assert_eq!(default.config_string(), "verbose=0");
        let set = DeviceConfig {
            threads: Some(3),
            verbose: 1,
            isa: Isa::Avx2,
        };
        assert_eq!(set.config_string(), "verbose=1,threads=3,isa=avx2");
    }

    /// The typed config cannot express a value Embree rejects, so the raw
    /// string is used to reach the failure path.
    #[test]
    fn a_config_embree_rejects_is_a_device_creation_error_with_its_message() {
        match Device::from_config_string("threads=many".into(), Isa::Auto) {
            Err(EmbreeError::DeviceCreation {
                config, message, ..
            }) => {
                assert_eq!(config, "threads=many");
                assert!(message.contains("integer"), "{message}");
            }
            Err(other) => panic!("unexpected error {other}"),
            Ok(_) => panic!("Embree accepted threads=many"),
        }
    }
}

//! The crate's error type and Embree's error codes (`enum RTCError`,
//! `rtcGetDeviceError` in Embree's `rtcore_device.h` documentation).

use std::fmt;

/// An `RTCError` code as Embree reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RtcErrorCode {
    Unknown,
    InvalidArgument,
    InvalidOperation,
    OutOfMemory,
    UnsupportedCpu,
    Cancelled,
    LevelZeroRaytracingSupportMissing,
    /// A code this crate does not know by name.
    Other(i32),
}

impl RtcErrorCode {
    /// Maps a raw `RTCError`; `None` for `RTC_ERROR_NONE`.
    pub(crate) fn from_raw(code: i32) -> Option<Self> {
        Some(match code {
            0 => return None,
            1 => Self::Unknown,
            2 => Self::InvalidArgument,
            3 => Self::InvalidOperation,
            4 => Self::OutOfMemory,
            5 => Self::UnsupportedCpu,
            6 => Self::Cancelled,
            7 => Self::LevelZeroRaytracingSupportMissing,
            other => Self::Other(other),
        })
    }
}

impl fmt::Display for RtcErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unknown => f.write_str("RTC_ERROR_UNKNOWN"),
            Self::InvalidArgument => f.write_str("RTC_ERROR_INVALID_ARGUMENT"),
            Self::InvalidOperation => f.write_str("RTC_ERROR_INVALID_OPERATION"),
            Self::OutOfMemory => f.write_str("RTC_ERROR_OUT_OF_MEMORY"),
            Self::UnsupportedCpu => f.write_str("RTC_ERROR_UNSUPPORTED_CPU"),
            Self::Cancelled => f.write_str("RTC_ERROR_CANCELLED"),
            Self::LevelZeroRaytracingSupportMissing => {
                f.write_str("RTC_ERROR_LEVEL_ZERO_RAYTRACING_SUPPORT_MISSING")
            }
            Self::Other(code) => write!(f, "RTCError {code}"),
        }
    }
}

/// Everything that can go wrong in this crate.
#[derive(Debug, thiserror::Error)]
pub enum EmbreeError {
    /// `rtcNewDevice` returned `NULL`.
    #[error("Embree could not create a device with config \"{config}\": {code}: {message}")]
    DeviceCreation {
        config: String,
        code: RtcErrorCode,
        message: String,
    },
    /// Embree set an error code during an API call sequence.
    #[error("Embree reported {code} while {during}: {message}")]
    Api {
        during: &'static str,
        code: RtcErrorCode,
        message: String,
    },
    /// A triangle names a vertex the mesh does not have. Embree itself would
    /// silently drop such a triangle at commit, so it is refused up front.
    #[error(
        "mesh {mesh}, triangle {triangle}: vertex index {index} is out of range \
         ({vertex_count} vertices)"
    )]
    IndexOutOfRange {
        mesh: usize,
        triangle: usize,
        index: u32,
        vertex_count: usize,
    },
    /// Redirecting or reading standard output for the statistics failed.
    #[error("cannot capture Embree's statistics output: {0}")]
    Capture(#[from] std::io::Error),
    /// Embree's statistics output did not have the expected shape.
    #[error("cannot parse Embree's statistics output: {reason}\n--- output ---\n{output}")]
    StatisticsParse { reason: String, output: String },
}

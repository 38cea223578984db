//! How Embree builds a scene: build quality and the robust flag
//! (`rtcSetSceneBuildQuality`, `rtcSetSceneFlags` in Embree's API docs).

use crate::ffi;

/// `RTCBuildQuality`: LOW (Morton / two-level), MEDIUM (binned SAH, Embree's
/// default), HIGH (SAH with spatial splits).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum BuildQuality {
    Low,
    #[default]
    Medium,
    High,
}

impl BuildQuality {
    pub(crate) fn raw(self) -> i32 {
        match self {
            Self::Low => 0,
            Self::Medium => 1,
            Self::High => 2,
        }
    }
}

/// Options of one scene build.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct SceneOptions {
    pub quality: BuildQuality,
    /// `RTC_SCENE_FLAG_ROBUST`: watertight-leaning triangle test, inclusive
    /// `[tnear, tfar]`, conservative box test (and no spatial splits).
    pub robust: bool,
}

impl SceneOptions {
    pub(crate) fn raw_flags(self) -> i32 {
        if self.robust {
            ffi::RTC_SCENE_FLAG_ROBUST
        } else {
            0
        }
    }
}

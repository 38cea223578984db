//! The rendering features a scene asks for; the renderer builds its passes from them.

use serde::Deserialize;

/// A rendering feature, named in manifests in snake_case (`hard_shadows`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Feature {
    Shading,
    HardShadows,
    Reflection,
    AreaLights,
    NormalInterpolation,
    Textures,
    MotionBlur,
    Bloom,
    Multisample,
    Glossy,
    Transparency,
}

impl Feature {
    pub const ALL: [Feature; 11] = [
        Feature::Shading,
        Feature::HardShadows,
        Feature::Reflection,
        Feature::AreaLights,
        Feature::NormalInterpolation,
        Feature::Textures,
        Feature::MotionBlur,
        Feature::Bloom,
        Feature::Multisample,
        Feature::Glossy,
        Feature::Transparency,
    ];

    /// The manifest spelling.
    pub fn name(self) -> &'static str {
        match self {
            Feature::Shading => "shading",
            Feature::HardShadows => "hard_shadows",
            Feature::Reflection => "reflection",
            Feature::AreaLights => "area_lights",
            Feature::NormalInterpolation => "normal_interpolation",
            Feature::Textures => "textures",
            Feature::MotionBlur => "motion_blur",
            Feature::Bloom => "bloom",
            Feature::Multisample => "multisample",
            Feature::Glossy => "glossy",
            Feature::Transparency => "transparency",
        }
    }
}

impl std::fmt::Display for Feature {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct Wrapper {
        feature: Feature,
    }

    #[test]
    fn every_name_deserializes_to_its_feature() {
        for feature in Feature::ALL {
            let parsed: Wrapper = toml::from_str(&format!("feature = \"{feature}\"")).unwrap();
            assert_eq!(parsed.feature, feature);
        }
    }
}

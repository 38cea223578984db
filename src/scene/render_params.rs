//! The sampling and post-processing parameters a manifest gives its render.

use serde::Deserialize;

/// Sample counts and depths; each is used only by the feature it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderParams {
    /// Camera rays per pixel (`multisample`, `motion_blur`).
    pub samples_per_pixel: u32,
    /// Shadow rays per extended light and shading point (`area_lights`).
    pub light_samples: u32,
    /// Reflection rays per glossy hit of a primary ray (`glossy`).
    pub glossy_samples: u32,
    /// Reflection and transmission rays followed per camera ray, at most.
    pub max_depth: u32,
    /// The bloom filter (`bloom`).
    pub bloom: BloomParams,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            samples_per_pixel: 1,
            light_samples: 16,
            glossy_samples: 8,
            max_depth: 4,
            bloom: BloomParams::default(),
        }
    }
}

/// Bloom: pixels brighter than `threshold` (luminance, linear) are blurred
/// with a filter of `radius` pixels and `strength` times the blur is added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BloomParams {
    pub threshold: f32,
    pub radius: u32,
    pub filter: BloomFilter,
    pub strength: f32,
}

impl Default for BloomParams {
    fn default() -> Self {
        Self {
            threshold: 1.0,
            radius: 8,
            filter: BloomFilter::Gaussian,
            strength: 0.5,
        }
    }
}

/// The blur kernel of the bloom.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BloomFilter {
    /// Equal weights over `2·radius + 1` pixels per axis.
    Box,
    /// A Gaussian of σ = radius / 2, cut at the radius.
    Gaussian,
}

//! Which sample count a sweep varies on a scene, and the scene and render
//! settings that give a render exactly `n` of those samples.
//!
//! A scene that samples one thing besides the pixel (an area light, or a
//! glossy lobe) is swept in that count at the pixel centres, so that the
//! count swept is the only random dimension of its render and its error
//! curve is that feature's alone. A scene that moves, or samples several
//! features, is swept in camera samples per pixel, each tracing one light
//! sample and one glossy sample: every sampled feature at once, `n`
//! samples of each per pixel.

use crate::render::RenderSettings;
use crate::render::pipeline::Passes;
use crate::render::sampling::Sampler;
use crate::scene::{Feature, Light, Scene};
use serde::Serialize;

/// The count a sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SweptCount {
    /// Camera samples per pixel, jittered over the pixel and the shutter,
    /// each with one light sample and one glossy sample.
    PixelSamples,
    /// Shadow rays per area light and shading point, at pixel centres.
    LightSamples,
    /// Reflection rays per glossy primary hit, at pixel centres.
    GlossySamples,
}

impl SweptCount {
    /// The count `scene` samples, or `None` when its render samples nothing.
    pub fn of(scene: &Scene) -> Option<Self> {
        let passes = Passes::for_scene(scene);
        let light = passes.shading
            && passes.area_lights
            && scene
                .lights
                .iter()
                .any(|l| !matches!(l, Light::Point { .. }));
        let glossy = passes.glossy
            && scene
                .materials
                .iter()
                .any(|m| m.roughness > 0.0 && m.mirror.max_element() > 0.0);
        let pixel = passes.multisample || passes.motion_blur;
        match (light, glossy, pixel) {
            _ if passes.motion_blur || (light && glossy) => Some(SweptCount::PixelSamples),
            (true, false, _) => Some(SweptCount::LightSamples),
            (false, true, _) => Some(SweptCount::GlossySamples),
            (false, false, true) => Some(SweptCount::PixelSamples),
            _ => None,
        }
    }

    /// Its name in tables.
    pub fn name(self) -> &'static str {
        match self {
            SweptCount::PixelSamples => "pixel samples",
            SweptCount::LightSamples => "light samples",
            SweptCount::GlossySamples => "glossy samples",
        }
    }

    /// `scene` made to take `count` of these samples, and the settings of a
    /// `resolution`² render of it with `sampler` and `seed`.
    pub fn configure(
        self,
        scene: &Scene,
        count: u32,
        resolution: u32,
        sampler: Sampler,
        seed: u64,
    ) -> (Scene, RenderSettings) {
        let mut scene = scene.clone();
        let mut settings = RenderSettings {
            seed,
            sampler,
            ..RenderSettings::square(resolution)
        };
        match self {
            SweptCount::PixelSamples => {
                scene.params.light_samples = 1;
                scene.params.glossy_samples = 1;
                settings.samples_per_pixel = Some(count);
            }
            SweptCount::LightSamples | SweptCount::GlossySamples => {
                scene.features.retain(|f| *f != Feature::Multisample);
                if self == SweptCount::LightSamples {
                    scene.params.light_samples = count;
                } else {
                    scene.params.glossy_samples = count;
                }
            }
        }
        (scene, settings)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene;

    #[test]
    fn every_sampled_scene_sweeps_the_count_it_samples() {
        let expected = [
            ("cornell-area", SweptCount::LightSamples),
            ("cornell-segment", SweptCount::LightSamples),
            ("analytic-area", SweptCount::LightSamples),
            ("cornell-glossy", SweptCount::GlossySamples),
            ("motion-blur", SweptCount::PixelSamples),
            ("cornell-sampled", SweptCount::PixelSamples),
        ];
        for (name, count) in expected {
            assert_eq!(SweptCount::of(&scene::load(name).unwrap()), Some(count));
        }
        assert_eq!(SweptCount::of(&scene::load("cornell").unwrap()), None);
    }

    #[test]
    fn a_configured_render_takes_exactly_the_count_swept() {
        let area = scene::load("cornell-area").unwrap();
        let (scene, settings) =
            SweptCount::LightSamples.configure(&area, 64, 32, Sampler::Stratified, 3);
        let passes = Passes::for_render(&scene, settings.samples_per_pixel);
        assert_eq!((passes.light_samples, passes.samples_per_pixel), (64, 1));
        assert!(
            !passes.multisample,
            "light samples are swept at pixel centres"
        );
        assert_eq!((settings.width, settings.seed), (32, 3));

        let sampled = scene::load("cornell-sampled").unwrap();
        let (scene, settings) =
            SweptCount::PixelSamples.configure(&sampled, 16, 32, Sampler::Independent, 0);
        let passes = Passes::for_render(&scene, settings.samples_per_pixel);
        assert_eq!(
            (
                passes.samples_per_pixel,
                passes.light_samples,
                passes.glossy_samples
            ),
            (16, 1, 1)
        );
        assert!(passes.multisample && passes.motion_blur && passes.glossy);
        assert_eq!(settings.sampler, Sampler::Independent);
    }
}

//! The passes a scene's render runs, derived from the features its manifest
//! lists and from what the scene holds: nothing the scene does not need is
//! computed (no light sampling for point lights only, no texture look-ups
//! without textures, no time samples when nothing moves, no reflection rays
//! without mirrors, no bloom unless asked).

use crate::scene::{Feature, Light, Scene};
use std::fmt;

/// Which parts of the render run for a scene, with their sample counts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Passes {
    /// Phong shading from every light (otherwise surfaces show their
    /// diffuse colour).
    pub shading: bool,
    /// One shadow ray per point light and shading point.
    pub hard_shadows: bool,
    /// Mirror reflection rays from materials with a mirror reflectance.
    pub reflection: bool,
    /// Segment and parallelogram lights sampled at `light_samples` points.
    pub area_lights: bool,
    /// Vertex normals interpolated where the mesh has them.
    pub normal_interpolation: bool,
    /// Diffuse colours from texture images.
    pub textures: bool,
    /// Moving meshes sampled at one shutter time per camera sample.
    pub motion_blur: bool,
    /// The bloom post-process.
    pub bloom: bool,
    /// Camera samples at jittered positions in the pixel.
    pub multisample: bool,
    /// Reflection rays spread around the mirror direction.
    pub glossy: bool,
    /// Rays continuing through surfaces of opacity below 1.
    pub transparency: bool,
    pub samples_per_pixel: u32,
    pub light_samples: u32,
    pub glossy_samples: u32,
    pub max_depth: u32,
}

impl Passes {
    /// The passes of `scene` with its own sample counts.
    pub fn for_scene(scene: &Scene) -> Self {
        Self::for_render(scene, None)
    }

    /// The passes of `scene`, with `samples_per_pixel` instead of the
    /// manifest's when given (more than one jitters the camera samples).
    pub fn for_render(scene: &Scene, samples_per_pixel: Option<u32>) -> Self {
        let has = |f: Feature| scene.features.contains(&f);
        let materials = &scene.materials;
        let meshes = std::iter::once(&scene.mesh).chain(scene.moving.iter().map(|m| &m.mesh));
        let reflection =
            has(Feature::Reflection) && materials.iter().any(|m| m.mirror.max_element() > 0.0);
        let motion_blur = has(Feature::MotionBlur) && !scene.moving.is_empty();
        let multisample = has(Feature::Multisample) || samples_per_pixel.is_some_and(|n| n > 1);
        let params = &scene.params;
        Self {
            shading: has(Feature::Shading),
            hard_shadows: has(Feature::HardShadows)
                && scene
                    .lights
                    .iter()
                    .any(|l| matches!(l, Light::Point { .. })),
            reflection,
            area_lights: has(Feature::AreaLights)
                && scene
                    .lights
                    .iter()
                    .any(|l| !matches!(l, Light::Point { .. })),
            normal_interpolation: has(Feature::NormalInterpolation)
                && meshes.clone().any(|m| m.normals.is_some()),
            textures: has(Feature::Textures)
                && scene.textures.iter().any(Option::is_some)
                && meshes.clone().any(|m| m.texcoords.is_some()),
            motion_blur,
            bloom: has(Feature::Bloom),
            multisample,
            glossy: reflection
                && has(Feature::Glossy)
                && materials
                    .iter()
                    .any(|m| m.mirror.max_element() > 0.0 && m.roughness > 0.0),
            transparency: has(Feature::Transparency) && materials.iter().any(|m| m.opacity < 1.0),
            samples_per_pixel: match samples_per_pixel {
                Some(n) => n.max(1),
                None if multisample || motion_blur => params.samples_per_pixel,
                None => 1,
            },
            light_samples: params.light_samples,
            glossy_samples: params.glossy_samples,
            max_depth: params.max_depth,
        }
    }
}

impl fmt::Display for Passes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let spp = self.samples_per_pixel;
        let names = [
            (true, format!("primary rays ({spp} per pixel)")),
            (self.multisample, "jittered pixel samples".into()),
            (
                self.motion_blur,
                "motion blur (1 shutter time per sample)".into(),
            ),
            (self.shading, "phong shading".into()),
            (
                self.hard_shadows,
                "hard shadows (1 occlusion ray per point light)".into(),
            ),
            (
                self.area_lights,
                format!(
                    "area lights ({} stratified shadow rays each)",
                    self.light_samples
                ),
            ),
            (self.normal_interpolation, "normal interpolation".into()),
            (self.textures, "texture mapping".into()),
            (
                self.reflection,
                format!("mirror reflection (depth {})", self.max_depth),
            ),
            (
                self.glossy,
                format!(
                    "glossy reflection ({} rays per primary hit)",
                    self.glossy_samples
                ),
            ),
            (self.transparency, "transparency".into()),
            (self.bloom, "bloom".into()),
        ];
        let list: Vec<&str> = names
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, n)| n.as_str())
            .collect();
        write!(f, "{}", list.join(", "))
    }
}

//! The passes a scene's render runs, derived from the features its manifest
//! lists (or its content, for a bare mesh) and from what the scene holds: nothing the scene does not need is
//! computed (no light sampling for point lights only, no texture look-ups
//! without textures, no time samples when nothing moves, no reflection rays
//! without mirrors, no bloom unless asked).

use crate::scene::{Feature, Scene, frame};
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
        let on = |f: Feature| has(f) && f.support(scene).is_ok();
        let reflection = on(Feature::Reflection);
        let motion_blur = on(Feature::MotionBlur);
        let multisample = has(Feature::Multisample) || samples_per_pixel.is_some_and(|n| n > 1);
        let params = &scene.params;
        Self {
            shading: has(Feature::Shading),
            hard_shadows: on(Feature::HardShadows),
            reflection,
            area_lights: on(Feature::AreaLights),
            normal_interpolation: on(Feature::NormalInterpolation),
            textures: on(Feature::Textures) && scene.textures.iter().any(Option::is_some),
            motion_blur,
            bloom: has(Feature::Bloom),
            multisample,
            glossy: reflection && on(Feature::Glossy),
            transparency: on(Feature::Transparency),
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

    /// Whether the pass of `feature` runs.
    pub fn runs(&self, feature: Feature) -> bool {
        match feature {
            Feature::Shading => self.shading,
            Feature::HardShadows => self.hard_shadows,
            Feature::Reflection => self.reflection,
            Feature::AreaLights => self.area_lights,
            Feature::NormalInterpolation => self.normal_interpolation,
            Feature::Textures => self.textures,
            Feature::MotionBlur => self.motion_blur,
            Feature::Bloom => self.bloom,
            Feature::Multisample => self.multisample,
            Feature::Glossy => self.glossy,
            Feature::Transparency => self.transparency,
        }
    }
}

/// What `render --explain` prints: the passes a render of `scene` runs (as
/// [`Passes`] shows them), where the scene's features come from, and for
/// each feature whether its pass runs and why, naming what in the scene it
/// acts on or what it lacks. A bare mesh lists every feature its content
/// could turn on ([`frame::FROM_CONTENT`]), a manifest the features it
/// names.
pub fn explain(scene: &Scene, samples_per_pixel: Option<u32>) -> String {
    let passes = Passes::for_render(scene, samples_per_pixel);
    let mut text = format!("{}: {passes}\n", scene.name);
    let candidates: Vec<Feature> = if scene.is_bare_mesh() {
        text += &format!(
            "features of the bare mesh {}: {} always, the others where its content has what they act on\n",
            scene.source.display(),
            frame::ALWAYS.map(Feature::name).join(" and ")
        );
        frame::ALWAYS
            .into_iter()
            .chain(frame::FROM_CONTENT)
            .collect()
    } else {
        text += &format!("features listed in {}:\n", scene.source.display());
        scene.features.clone()
    };
    for feature in candidates {
        let line = match (passes.runs(feature), feature.support(scene)) {
            (true, Ok(why) | Err(why)) => format!("on: {why}"),
            (false, Err(why)) => format!("off: {why}"),
            (false, Ok(why)) => format!("off, though {why}"),
        };
        text += &format!("  {feature}: {line}\n");
    }
    if passes.multisample && !scene.features.contains(&Feature::Multisample) {
        text += &format!(
            "  {}: on: {} samples per pixel asked for\n",
            Feature::Multisample,
            passes.samples_per_pixel
        );
    }
    text
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

//! The direct light at a surface point: the ambient term plus the Phong
//! response to each light sample that faces the point and that its
//! shadow ray, where the pass casts shadows, finds unblocked.
//!
//! A point shaded on its own asks each shadow ray as it draws the light
//! sample, then shades the sample while the query runs. A [`super::batch`]
//! of camera samples plans its points' light paths first and asks their
//! shadow rays one after another, where every light is taken whole, so
//! that planning draws no random numbers.

use super::area_lights::{self, LightSample};
use super::debug::ray_paths::RaySegment;
use super::surface::SurfacePoint;
use super::{PathState, Renderer, shading, shadows};
use crate::scene::{Light, Material};
use crate::trace::Intersector;
use glam::Vec3;

/// A light sample seen from a surface point it faces.
#[derive(Clone, Copy, Debug)]
pub(super) struct Facing {
    to_light: Vec3,
    n_dot_l: f32,
    intensity: Vec3,
    distance_squared: f32,
}

impl Facing {
    /// How `sample` stands from `surface`; `None` when the point is behind
    /// the light's emitting side or the light behind the point (then it
    /// adds nothing and needs no shadow ray).
    #[inline(always)]
    fn of(surface: &SurfacePoint, sample: &LightSample) -> Option<Self> {
        let intensity = sample.intensity_towards(surface.position)?;
        let offset = sample.position - surface.position;
        let to_light = offset.normalize_or_zero();
        let n_dot_l = shading::facing_cosine(surface, to_light)?;
        Some(Self {
            to_light,
            n_dot_l,
            intensity,
            distance_squared: offset.length_squared(),
        })
    }

    /// The Phong response at `surface`, of diffuse colour `diffuse`.
    #[inline(always)]
    fn response(&self, material: &Material, diffuse: Vec3, surface: &SurfacePoint) -> Vec3 {
        let irradiance = shading::inverse_square(self.intensity, self.distance_squared);
        shading::phong(
            material,
            diffuse,
            surface,
            self.to_light,
            self.n_dot_l,
            irradiance,
        )
    }
}

/// A light taken whole, planned for a surface point before its shadow
/// ray is asked.
#[derive(Clone, Copy, Debug)]
pub(super) struct LightPath {
    position: Vec3,
    facing: Facing,
}

impl<I: Intersector + ?Sized> Renderer<'_, I> {
    /// Whether the pass samples `light` over its area (or takes it whole).
    fn samples_area(&self, light: &Light) -> bool {
        self.passes.area_lights && !matches!(light, Light::Point { .. })
    }

    /// Whether every light is taken whole: a batch then plans its
    /// points' light paths before it asks their shadow rays. An area
    /// light's samples are drawn one after another from each camera
    /// sample's stream, a chain of dependent steps that asking each
    /// shadow ray as its sample is drawn hides.
    pub(super) fn plans_light_ahead(&self) -> bool {
        !self
            .scene
            .lights
            .iter()
            .any(|light| self.samples_area(light))
    }

    /// The direct light at `surface`, each shadow ray asked as its light
    /// sample is drawn.
    pub(super) fn direct_light(
        &self,
        surface: &SurfacePoint,
        diffuse: Vec3,
        state: &mut PathState,
    ) -> Vec3 {
        let material = &self.scene.materials[surface.material as usize];
        let mut sum = shading::ambient(diffuse);
        for light in &self.scene.lights {
            let sampled = self.samples_area(light);
            let (count, shadowed) = if sampled {
                (
                    area_lights::sample_count(light, self.passes.light_samples),
                    true,
                )
            } else {
                (1, self.passes.hard_shadows)
            };
            for index in 0..count {
                let sample = if sampled {
                    let sampler = self.settings.sampler;
                    area_lights::sample(light, index, count, sampler, &mut state.stream)
                } else {
                    area_lights::whole(light)
                };
                let Some(facing) = Facing::of(surface, &sample) else {
                    continue;
                };
                if shadowed {
                    let visible = shadows::light_visible(
                        self.scene,
                        self.layers,
                        surface,
                        sample.position,
                        state.time,
                    );
                    if let Some(log) = &mut state.log {
                        log.push(RaySegment::shadow(surface, sample.position, !visible));
                    }
                    if !visible {
                        continue;
                    }
                }
                // Shaded after the shadow ray is asked, not before: the
                // shading then runs while the query is in flight, and
                // shadowed samples skip it.
                sum += facing.response(material, diffuse, surface);
            }
        }
        sum
    }

    /// Each light, taken whole, that faces `surface`, in order (see
    /// [`Self::plans_light_ahead`]).
    pub(super) fn whole_light_paths(&self, surface: &SurfacePoint, paths: &mut Vec<LightPath>) {
        for light in &self.scene.lights {
            let sample = area_lights::whole(light);
            if let Some(facing) = Facing::of(surface, &sample) {
                paths.push(LightPath {
                    position: sample.position,
                    facing,
                });
            }
        }
    }

    /// The direct light at `surface` from `paths`, planned for it by
    /// [`Self::whole_light_paths`]: the sum [`Self::direct_light`] makes,
    /// the shadow rays asked at shutter time `time`.
    pub(super) fn lit_by(
        &self,
        surface: &SurfacePoint,
        diffuse: Vec3,
        paths: &[LightPath],
        time: f32,
    ) -> Vec3 {
        let material = &self.scene.materials[surface.material as usize];
        let mut sum = shading::ambient(diffuse);
        for path in paths {
            let visible = !self.passes.hard_shadows
                || shadows::light_visible(self.scene, self.layers, surface, path.position, time);
            if visible {
                sum += path.facing.response(material, diffuse, surface);
            }
        }
        sum
    }
}

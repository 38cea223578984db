//! `raycheck compare`'s ray sets, traced through every backend at once.
//!
//! The rays: one primary ray through each pixel centre of an N×N view from
//! the scene's camera; from each primary hit, a shadow ray to every light
//! and a mirror-reflection ray (whatever the material, to exercise secondary
//! rays everywhere). Secondary rays are spawned from the first backend's
//! hit, so every backend sees the very same rays.

use super::checked::{CheckLog, Checked};
use crate::backends::Backend;
use crate::render::surface::SurfacePoint;
use crate::scene::Scene;
use crate::trace::Intersector;
use rayon::prelude::*;
use serde::Serialize;

/// The kinds of ray set the harness makes, each checked and reported on
/// its own: `compare` traces primary, shadow and reflection rays; `perf`
/// primary, shadow and diffuse; `raycheck rays` writes any of them, or a
/// stability case's.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RaySet {
    /// Through the pixel centres of the scene's camera (closest hit).
    Primary,
    /// From each primary hit to each light (any hit).
    Shadow,
    /// The mirror reflection of each primary ray (closest hit).
    Reflection,
    /// A cosine-distributed bounce from each primary hit (closest hit).
    Diffuse,
    /// A numerical-stability case's rays (closest hit).
    StabilityCase,
    /// The same rays of a stability case, asked the any-hit query.
    StabilityCaseAnyHit,
}

impl RaySet {
    /// Whether the set asks for occlusion (any hit) rather than the
    /// closest hit.
    pub fn is_any_hit(self) -> bool {
        matches!(self, RaySet::Shadow | RaySet::StabilityCaseAnyHit)
    }

    /// The set's name in tables and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            RaySet::Primary => "primary",
            RaySet::Shadow => "shadow",
            RaySet::Reflection => "reflection",
            RaySet::Diffuse => "diffuse",
            RaySet::StabilityCase => "stability case",
            RaySet::StabilityCaseAnyHit => "stability case any-hit",
        }
    }
}

/// Traces the compare ray sets of `scene` through `backends`; one log per
/// ray set.
pub fn compare(
    scene: &Scene,
    backends: &[&dyn Backend],
    resolution: u32,
) -> Vec<(RaySet, CheckLog)> {
    let primary = Checked::new(backends.to_vec());
    let shadow = Checked::new(backends.to_vec());
    let reflection = Checked::new(backends.to_vec());
    (0..resolution).into_par_iter().for_each(|y| {
        for x in 0..resolution {
            let ray = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, resolution, resolution);
            let Some(hit) = primary.intersect(&ray) else {
                continue;
            };
            let surface = SurfacePoint::new(&scene.mesh, &ray, &hit);
            for light in &scene.lights {
                shadow.occluded(&surface.shadow_ray(light.representative_point()));
            }
            reflection.intersect(&surface.reflection_ray());
        }
    });
    vec![
        (RaySet::Primary, primary.into_log()),
        (RaySet::Shadow, shadow.into_log()),
        (RaySet::Reflection, reflection.into_log()),
    ]
}

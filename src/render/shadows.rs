//! Shadows: one any-hit query (`occluded`) from the surface towards a point
//! on a light, over every mesh layer at the sample's shutter time.

use super::motion_blur;
use super::surface::SurfacePoint;
use crate::scene::Scene;
use crate::trace::Intersector;
use glam::Vec3;

/// Whether `light_position` is visible from `surface` at shutter time `time`.
pub fn light_visible<I: Intersector + ?Sized>(
    scene: &Scene,
    layers: &[&I],
    surface: &SurfacePoint,
    light_position: Vec3,
    time: f32,
) -> bool {
    !motion_blur::occluded(scene, layers, &surface.shadow_ray(light_position), time)
}

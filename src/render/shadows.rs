//! Hard shadows: one any-hit query (`occluded`) from the surface to each
//! point light.

use super::surface::SurfacePoint;
use crate::trace::Intersector;
use glam::Vec3;

/// Whether `light_position` is visible from `surface`.
pub fn light_visible<I: Intersector + ?Sized>(
    intersector: &I,
    surface: &SurfacePoint,
    light_position: Vec3,
) -> bool {
    !intersector.occluded(&surface.shadow_ray(light_position))
}

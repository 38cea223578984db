//! Transparency (Whitted 1980, without refraction): a surface of opacity α
//! shows `α·local + (1 − α)·behind`, where `behind` is traced by a ray
//! continuing in the same direction from the far side of the surface, down
//! to the maximum depth. Shadow rays treat every surface as opaque.

use super::surface::SurfacePoint;
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use glam::Vec3;

/// The ray that continues through `surface`, starting just behind it
/// (the Wächter–Binder offset, to the side away from the viewer).
pub fn continuation_ray(surface: &SurfacePoint) -> Ray {
    Ray::new(
        offset_ray_origin(surface.position, -surface.geometric_normal),
        -surface.to_viewer,
    )
}

/// Blends a surface's own colour with what lies behind it.
pub fn blend(opacity: f32, local: Vec3, behind: Vec3) -> Vec3 {
    opacity * local + (1.0 - opacity) * behind
}

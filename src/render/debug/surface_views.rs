//! What the primary hit of each pixel's centre ray (shutter time 0) knows
//! about its surface, as colour: the shading normal as 0.5·n + 0.5, the
//! barycentrics (u, v, 1 − u − v) as RGB, or the texture coordinates as
//! (u, v, 0), wrapped into [0, 1) as the texture look-up wraps them.
//! Misses, and triangles without texture coordinates, are black.

use super::{DebugImage, display};
use crate::render::image::Image;
use crate::render::{Renderer, textures};
use crate::trace::Intersector;
use glam::Vec3;

/// Which surface attribute a view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attribute {
    Normal,
    Barycentrics,
    Texcoords,
}

/// The attribute's colour at every pixel.
pub fn draw<I: Intersector + ?Sized>(renderer: &Renderer<I>, attribute: Attribute) -> DebugImage {
    let settings = &renderer.settings;
    let image = Image::par_from_fn(settings.width, settings.height, |x, y| {
        let ray = renderer.scene.camera.ray(
            x as f32 + 0.5,
            y as f32 + 0.5,
            settings.width,
            settings.height,
        );
        let Some(hit) = renderer.closest_hit(&ray, 0.0) else {
            return Vec3::ZERO;
        };
        let (surface, mesh) = renderer.surface(&ray, &hit);
        let colour = match attribute {
            Attribute::Normal => 0.5 * surface.normal + 0.5,
            Attribute::Barycentrics => Vec3::new(surface.u, surface.v, 1.0 - surface.u - surface.v),
            Attribute::Texcoords => textures::texcoord(mesh, surface.prim, surface.u, surface.v)
                .map_or(Vec3::ZERO, |uv| (uv - uv.floor()).extend(0.0)),
        };
        display(colour)
    });
    let legend = match attribute {
        Attribute::Normal if renderer.passes.normal_interpolation => {
            "interpolated shading normal n, facing the viewer, as 0.5·n + 0.5"
        }
        Attribute::Normal => "geometric normal n, facing the viewer, as 0.5·n + 0.5",
        Attribute::Barycentrics => "barycentrics (u, v, 1 − u − v) as (red, green, blue)",
        Attribute::Texcoords => {
            "texture coordinates (u, v) wrapped into [0, 1) as (red, green); black: none"
        }
    };
    DebugImage {
        image,
        legend: legend.to_string(),
    }
}

//! The bloom mask: which pixels of the render before bloom take part in
//! it — red where the luminance is above the scene's bloom threshold,
//! blue where it is not.

use super::{DebugImage, display};
use crate::render::Renderer;
use crate::render::bloom;
use crate::render::image::Image;
use crate::trace::Intersector;
use glam::Vec3;

/// The mask of `renderer`'s radiance, with the bright pixel count.
pub fn draw<I: Intersector + ?Sized>(renderer: &Renderer<I>) -> DebugImage {
    let params = &renderer.scene.params.bloom;
    let radiance = renderer.render_radiance();
    let bright: Vec<bool> = radiance
        .pixels
        .iter()
        .map(|&c| bloom::is_bright(c, params))
        .collect();
    let count = bright.iter().filter(|&&b| b).count();
    let image = Image {
        pixels: bright
            .iter()
            .map(|&b| display(if b { Vec3::X } else { Vec3::Z }))
            .collect(),
        ..radiance
    };
    DebugImage {
        legend: format!(
            "red: luminance above the bloom threshold {} ({count} of {} pixels); blue: below",
            params.threshold,
            image.pixels.len()
        ),
        image,
    }
}

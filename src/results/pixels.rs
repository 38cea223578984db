//! How two backends' renders of one scene differ, pixel by pixel, and
//! which rays explain the pixels that differ beyond floating-point noise.
//!
//! Where both backends hit the same triangles, their hits differ only in
//! the last bits of t, u and v (relative t errors below 4e-6; the referee
//! would flag more). Shading takes the hit point from u and v, so it moves
//! by a few ulps of the coordinates (~1e-6 relative); irradiance goes with
//! 1/d², doubling that, and the sharpest highlight (shininess 1000, the
//! mirror) raises r·v to the 1000th power, multiplying a direction error
//! of ~1e-7 by 1000. Secondary rays start from those points, so every
//! bounce can add as much again, up to the maximum depth of 4. That is at
//! most ~1e-3 relative ([`RELATIVE_BOUND`]); the random numbers never
//! depend on hits, so sampling adds nothing. A pixel beyond the bound must
//! have a ray the backends answered differently: a different triangle, a
//! hit against a miss, a shadow ray blocked or not.

use crate::backends::Backend;
use crate::check::{Answer, Checked};
use crate::render::debug::heat::ramp;
use crate::render::image::Image;
use crate::render::{RenderSettings, Renderer};
use crate::scene::Scene;
use glam::Vec3;
use serde::Serialize;

/// The largest difference two backends' renders may show per channel,
/// relative to the pixel's value, when every ray got the same triangle.
pub const RELATIVE_BOUND: f32 = 1e-3;
/// Below this linear value (1/20 of an 8-bit sRGB step near black) a
/// difference is invisible and relative errors mean nothing.
pub const ABSOLUTE_FLOOR: f32 = 1e-5;
/// The difference map's scale: log10 of the relative difference from
/// 10^-MAP_DECADES (darkest) to 1 (brightest).
pub const MAP_DECADES: f32 = 7.0;

/// The largest channel difference beyond the floor, relative to the pixel.
pub fn relative_difference(a: Vec3, b: Vec3) -> f32 {
    let diff = (a - b).abs().max_element();
    if diff <= ABSOLUTE_FLOOR {
        0.0
    } else {
        diff / a.abs().max(b.abs()).max_element()
    }
}

/// Two renders of one scene compared.
#[derive(Clone, Debug, Default, Serialize)]
pub struct PixelDifference {
    pub pixels: usize,
    /// Pixels whose radiance differs in any bit.
    pub differing: usize,
    /// The largest per-channel difference (linear radiance).
    pub largest: f32,
    /// Pixels beyond [`RELATIVE_BOUND`].
    pub beyond_bound: usize,
    /// Of those, the pixels one of whose own rays the backends answered
    /// differently, both answers admissible, by that ray's kind (the first
    /// found, in the order primary, shadow, secondary).
    pub explained_by_primary: usize,
    pub explained_by_shadow: usize,
    pub explained_by_secondary: usize,
    /// Pixels beyond the bound with no such ray: a fault of a backend.
    pub unexplained: usize,
}

/// Compares the radiance (before post-processing, so bloom cannot carry a
/// pixel's difference to its neighbours) of `scene` rendered through
/// `first` and through `second` (one backend per mesh layer each), and
/// re-traces every pixel beyond the bound through both at once to find
/// the rays that explain it. Returns the comparison and the difference
/// map: black where identical (or both below the visible floor), then
/// log10 of the relative difference on a viridis ramp from 1e-7 (dark) to
/// 1 (yellow), beyond-bound pixels in red.
pub fn compare_renders(
    scene: &Scene,
    first: &[&dyn Backend],
    second: &[&dyn Backend],
    settings: &RenderSettings,
) -> (PixelDifference, Image) {
    let a = Renderer::new(scene, first, settings).render_radiance();
    let b = Renderer::new(scene, second, settings).render_radiance();
    let mut difference = PixelDifference {
        pixels: a.pixels.len(),
        ..Default::default()
    };
    let mut map = Image::new(a.width, a.height);
    let eye = scene.camera.ray(0.5, 0.5, 1, 1).origin;
    for (index, (&p, &q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        let diff = (p - q).abs().max_element();
        if diff == 0.0 {
            continue;
        }
        difference.differing += 1;
        difference.largest = difference.largest.max(diff);
        let relative = relative_difference(p, q);
        if relative > 0.0 {
            let level = (relative.log10() + MAP_DECADES) / MAP_DECADES;
            map.pixels[index] = crate::render::debug::display(ramp(level));
        }
        if relative <= RELATIVE_BOUND {
            continue;
        }
        difference.beyond_bound += 1;
        map.pixels[index] = crate::render::debug::display(Vec3::X);
        let (x, y) = (index as u32 % a.width, index as u32 / a.width);
        match explaining_ray(scene, first, second, settings, x, y, eye) {
            Some(RayKind::Primary) => difference.explained_by_primary += 1,
            Some(RayKind::Shadow) => difference.explained_by_shadow += 1,
            Some(RayKind::Secondary) => difference.explained_by_secondary += 1,
            None => difference.unexplained += 1,
        }
    }
    (difference, map)
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum RayKind {
    Primary,
    Shadow,
    Secondary,
}

/// The kind of the first of pixel (`x`, `y`)'s rays (primary before shadow
/// before secondary) on which the two backends' answers differ and both
/// are admissible.
fn explaining_ray(
    scene: &Scene,
    first: &[&dyn Backend],
    second: &[&dyn Backend],
    settings: &RenderSettings,
    x: u32,
    y: u32,
    eye: Vec3,
) -> Option<RayKind> {
    let checks: Vec<Checked> = first
        .iter()
        .zip(second)
        .map(|(&a, &b)| Checked::new(vec![a, b]))
        .collect();
    let layers: Vec<&Checked> = checks.iter().collect();
    Renderer::new(scene, &layers, settings).pixel(x, y);
    checks
        .into_iter()
        .zip(scene.meshes())
        .flat_map(|(check, mesh)| {
            let log = check.into_log();
            let judgements = log.judge(mesh);
            log.records
                .into_iter()
                .zip(judgements)
                .filter(|(record, judged)| {
                    record.disagreement && judged.iter().all(|j| j.is_admissible())
                })
                .map(|(record, _)| match record.answers[0] {
                    Answer::Occluded(_) => RayKind::Shadow,
                    Answer::Closest(_) if record.ray.origin == eye => RayKind::Primary,
                    Answer::Closest(_) => RayKind::Secondary,
                })
                .collect::<Vec<_>>()
        })
        .min()
}

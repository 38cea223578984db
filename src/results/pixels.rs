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
use crate::check::{Answer, Checked, Judgement};
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
    /// Pixels beyond [`RELATIVE_BOUND`], each counted once below by what
    /// explains it, in this order.
    pub beyond_bound: usize,
    /// A ray of the pixel the first backend answered wrongly.
    pub first_wrong: usize,
    /// A ray of the pixel the second backend answered wrongly.
    pub second_wrong: usize,
    /// A ray both backends were asked and answered differently, both
    /// answers admissible, by that ray's kind.
    pub ambiguous_primary: usize,
    pub ambiguous_shadow: usize,
    pub ambiguous_secondary: usize,
    /// Each backend right on every ray of its own render of the pixel: the
    /// renders asked different secondary rays, spawned from hit points a
    /// few ulps apart, and got different answers, each admissible (a
    /// shadow ray grazing an edge from one point and not from the other).
    pub divergent_rays: usize,
    /// None of these: a fault the comparison cannot place.
    pub unexplained: usize,
}

/// Compares the radiance (before post-processing, so bloom cannot carry a
/// pixel's difference to its neighbours) of `scene` rendered through
/// `first` and through `second` (one backend per mesh layer each), and
/// re-traces every pixel beyond the bound through both at once, each
/// render's own rays in turn, to find what explains it. Returns the
/// comparison and the difference map: black where identical (or both
/// below the visible floor), then log10 of the relative difference on a
/// viridis ramp from 1e-7 (dark) to 1 (yellow), beyond-bound pixels red.
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
        let ours_first = judge_pixel(scene, first, second, settings, (x, y), eye);
        let theirs_first = judge_pixel(scene, second, first, settings, (x, y), eye);
        let slot = match (ours_first, theirs_first) {
            (Pixel::Wrong { first: true }, _) | (_, Pixel::Wrong { first: false }) => {
                &mut difference.first_wrong
            }
            (Pixel::Wrong { .. }, _) | (_, Pixel::Wrong { .. }) => &mut difference.second_wrong,
            (Pixel::Ambiguous(kind), _) | (_, Pixel::Ambiguous(kind)) => match kind {
                RayKind::Primary => &mut difference.ambiguous_primary,
                RayKind::Shadow => &mut difference.ambiguous_shadow,
                RayKind::Secondary => &mut difference.ambiguous_secondary,
            },
            (Pixel::AllRight, Pixel::AllRight) => &mut difference.divergent_rays,
            _ => &mut difference.unexplained,
        };
        *slot += 1;
    }
    (difference, map)
}

#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum RayKind {
    Primary,
    Shadow,
    Secondary,
}

/// What one backend's render of a pixel showed when both backends
/// answered its every ray.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Pixel {
    /// A backend answered a ray wrongly (`first`: the one whose render it
    /// is).
    Wrong { first: bool },
    /// The backends answered a ray differently, both admissibly; the first
    /// such ray's kind, in the order primary, shadow, secondary.
    Ambiguous(RayKind),
    /// Every ray answered alike and right (or admissibly).
    AllRight,
    /// Something the referee judged neither way: a distance off.
    Other,
}

/// Renders pixel `(x, y)` through `render` with `other` asked every query
/// too, and judges every answer.
fn judge_pixel(
    scene: &Scene,
    render: &[&dyn Backend],
    other: &[&dyn Backend],
    settings: &RenderSettings,
    (x, y): (u32, u32),
    eye: Vec3,
) -> Pixel {
    let checks: Vec<Checked> = render
        .iter()
        .zip(other)
        .map(|(&a, &b)| Checked::recording_every_query(vec![a, b]))
        .collect();
    let layers: Vec<&Checked> = checks.iter().collect();
    Renderer::new(scene, &layers, settings).pixel(x, y);
    let mut ambiguous: Option<RayKind> = None;
    let mut verdict = Pixel::AllRight;
    for (check, mesh) in checks.into_iter().zip(scene.meshes()) {
        let log = check.into_log();
        for (record, judged) in log.records.iter().zip(log.judge(mesh)) {
            if judged[0] == Judgement::Wrong {
                return Pixel::Wrong { first: true };
            }
            if judged[1] == Judgement::Wrong {
                return Pixel::Wrong { first: false };
            }
            if !judged.iter().all(|j| j.is_admissible()) {
                verdict = Pixel::Other;
            } else if record.disagreement {
                let kind = match record.answers[0] {
                    Answer::Occluded(_) => RayKind::Shadow,
                    Answer::Closest(_) if record.ray.origin == eye => RayKind::Primary,
                    Answer::Closest(_) => RayKind::Secondary,
                };
                ambiguous = Some(ambiguous.map_or(kind, |k| k.min(kind)));
            }
        }
    }
    ambiguous.map_or(verdict, Pixel::Ambiguous)
}

//! A heat map of traversal work: how many BVH nodes the closest-hit
//! traversal of each pixel's centre ray visits, over every mesh layer
//! (shutter time 0), mapped to a colour ramp from the fewest (dark purple)
//! to the most (yellow). Any of our BVHs can be read ([`BvhView`]): the
//! binary ones count nodes, the wide one nodes and leaf blocks.

use super::{DebugImage, display};
use crate::bvh::BvhView;
use crate::geometry::{Hit, Ray};
use crate::render::image::Image;
use crate::render::{RenderSettings, motion_blur};
use crate::scene::Scene;
use crate::trace::Intersector;
use glam::Vec3;
use std::sync::atomic::{AtomicU32, Ordering};

/// Viridis (van der Walt and Smith 2015) at five evenly spaced stops, as
/// display colours: ordered in lightness and readable by colour-blind eyes.
const RAMP: [Vec3; 5] = [
    Vec3::new(0.267, 0.005, 0.329),
    Vec3::new(0.231, 0.322, 0.545),
    Vec3::new(0.129, 0.569, 0.549),
    Vec3::new(0.369, 0.788, 0.384),
    Vec3::new(0.992, 0.906, 0.145),
];

/// The ramp's display colour at `f` in [0, 1].
pub fn ramp(f: f32) -> Vec3 {
    let x = f.clamp(0.0, 1.0) * (RAMP.len() - 1) as f32;
    let i = (x as usize).min(RAMP.len() - 2);
    RAMP[i].lerp(RAMP[i + 1], x - i as f32)
}

/// Our BVH, adding up the nodes its closest-hit queries visit.
struct Counting<'a> {
    bvh: &'a dyn BvhView,
    visits: AtomicU32,
}

impl Intersector for Counting<'_> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let mut visits = 0u32;
        let hit = self.bvh.intersect_counting(ray, &mut visits);
        self.visits.fetch_add(visits, Ordering::Relaxed);
        hit
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.bvh.occluded(ray)
    }
}

/// The nodes visited for the centre ray of pixel (`x`, `y`), over every layer.
pub fn visits(
    scene: &Scene,
    bvhs: &[&dyn BvhView],
    x: u32,
    y: u32,
    settings: &RenderSettings,
) -> u32 {
    let counters: Vec<Counting> = bvhs
        .iter()
        .map(|&bvh| Counting {
            bvh,
            visits: AtomicU32::new(0),
        })
        .collect();
    let layers: Vec<&Counting> = counters.iter().collect();
    let (width, height) = (settings.width, settings.height);
    let ray = scene
        .camera
        .ray(x as f32 + 0.5, y as f32 + 0.5, width, height);
    motion_blur::intersect(scene, &layers, &ray, 0.0);
    counters
        .iter()
        .map(|c| c.visits.load(Ordering::Relaxed))
        .sum()
}

/// The heat map; its legend states the largest and mean count.
pub fn draw(scene: &Scene, bvhs: &[&dyn BvhView], settings: &RenderSettings) -> DebugImage {
    let counts = Image::par_from_fn(settings.width, settings.height, |x, y| {
        Vec3::splat(visits(scene, bvhs, x, y, settings) as f32)
    });
    let max = counts.pixels.iter().map(|c| c.x).fold(0.0, f32::max);
    let mean = counts.pixels.iter().map(|c| c.x as f64).sum::<f64>() / counts.pixels.len() as f64;
    let image = Image {
        pixels: counts
            .pixels
            .iter()
            .map(|c| display(ramp(if max > 0.0 { c.x / max } else { 0.0 })))
            .collect(),
        ..counts
    };
    DebugImage {
        image,
        legend: format!(
            "BVH nodes visited per pixel (closest hit of the centre ray): \
             0 dark purple to {max} yellow (viridis), mean {mean:.1}"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_runs_from_dark_to_light() {
        assert_eq!(ramp(0.0), RAMP[0]);
        assert_eq!(ramp(1.0), RAMP[4]);
        assert_eq!(ramp(2.0), RAMP[4]);
        let lightness = |c: Vec3| c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
        let steps: Vec<f32> = (0..=20).map(|i| lightness(ramp(i as f32 / 20.0))).collect();
        assert!(steps.windows(2).all(|w| w[0] < w[1]), "{steps:?}");
    }
}

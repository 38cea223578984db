//! The order an image's camera rays are traced in: a row's camera samples
//! a batch at a time, the closest-hit queries of the batch's camera rays
//! asked one after another; then every hit's surface resolved; then each
//! hit's direct light ([`super::direct_light`]), where every light is
//! taken whole from light paths planned for all the batch's hits before
//! their shadow rays are asked; and only then the rest of each sample's
//! path (reflections, transparency) traced as [`Renderer::pixel`] traces
//! it.
//!
//! Asked one by one among the shading, each query waits for the shading
//! before it; asked back to back, a processor starts the next query before
//! the last has finished, as wavefront renderers order their work on GPUs
//! (Laine, Karras and Aila, "Megakernels Considered Harmful: Wavefront
//! Path Tracing on GPUs", HPG 2013). The queries, their answers, the
//! random numbers each sample draws and the order of every addition are
//! those of [`Renderer::pixel`], so the pixels are the same bits.

use super::direct_light::LightPath;
use super::motion_blur::LayerHit;
use super::surface::SurfacePoint;
use super::{PathState, Renderer};
use crate::geometry::Ray;
use crate::trace::Intersector;
use glam::Vec3;

/// Camera samples per batch, as many whole pixels as fit (one pixel
/// whose samples are more is a batch of its own): with 8, 16, 32 or 64
/// the Cornell box's and the monkey's renders took the same time within
/// 2% (three runs each, one thread, Xeon), so the batch is kept small.
const BATCH_SAMPLES: usize = 32;

/// A camera sample's first hit, resolved: its surface, its diffuse
/// colour, where its light paths end in the batch's list, and the light
/// it sends back once they are asked.
struct Lit {
    surface: SurfacePoint,
    diffuse: Vec3,
    paths_end: usize,
    color: Vec3,
}

/// One batch's work, kept between batches so that a row allocates once.
#[derive(Default)]
struct Batch {
    samples: Vec<(Ray, PathState)>,
    hits: Vec<Option<LayerHit>>,
    /// One per sample that hit, in order.
    lit: Vec<Lit>,
    paths: Vec<LightPath>,
}

impl<I: Intersector + ?Sized> Renderer<'_, I> {
    /// Fills `row`, the pixels of image row `y`, batch by batch.
    pub(super) fn fill_row(&self, y: u32, row: &mut [Vec3]) {
        let count = self.passes.samples_per_pixel as usize;
        let pixels_per_batch = (BATCH_SAMPLES / count).max(1);
        let mut batch = Batch::default();
        let firsts = (0..).step_by(pixels_per_batch);
        for (pixels, first) in row.chunks_mut(pixels_per_batch).zip(firsts) {
            batch.samples.clear();
            for x in first..first + pixels.len() as u32 {
                for sample in 0..count as u32 {
                    batch.samples.push(self.camera_sample(x, y, sample));
                }
            }
            self.trace_batch(&mut batch);
            let mut lit = batch.lit.iter();
            let mut samples = batch.samples.iter_mut().zip(&batch.hits);
            for pixel in pixels.iter_mut() {
                let mut sum = Vec3::ZERO;
                for ((_, state), hit) in samples.by_ref().take(count) {
                    sum += match hit.and_then(|_| lit.next()) {
                        Some(lit) => self.beyond(&lit.surface, lit.color, 0, state),
                        // A camera ray that leaves the scene brings back nothing.
                        None => Vec3::ZERO,
                    };
                }
                *pixel = sum / count as f32;
            }
        }
    }

    /// The batch's camera rays' closest hits, back to back; then each
    /// hit's surface, and its direct light where the pass shades.
    fn trace_batch(&self, batch: &mut Batch) {
        batch.hits.clear();
        batch.hits.extend(
            batch
                .samples
                .iter()
                .map(|(ray, state)| self.closest_hit(ray, state.time)),
        );
        let plan = self.passes.shading && self.plans_light_ahead();
        batch.lit.clear();
        batch.paths.clear();
        for ((ray, _), hit) in batch.samples.iter().zip(&batch.hits) {
            if let Some(hit) = hit {
                let (surface, diffuse) = self.lit_surface(ray, hit);
                if plan {
                    self.whole_light_paths(&surface, &mut batch.paths);
                }
                batch.lit.push(Lit {
                    surface,
                    diffuse,
                    paths_end: batch.paths.len(),
                    color: diffuse,
                });
            }
        }
        if !self.passes.shading {
            return;
        }
        let states = batch.samples.iter_mut().zip(&batch.hits);
        let hit_states = states.filter_map(|((_, state), hit)| hit.map(|_| state));
        let mut first = 0;
        for (lit, state) in batch.lit.iter_mut().zip(hit_states) {
            lit.color = if plan {
                let paths = &batch.paths[first..lit.paths_end];
                self.lit_by(&lit.surface, lit.diffuse, paths, state.time)
            } else {
                self.direct_light(&lit.surface, lit.diffuse, state)
            };
            first = lit.paths_end;
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::bvh::wide::WideBvh;
    use crate::render::{RenderSettings, Renderer};
    use crate::scene;
    use glam::Vec3;

    /// Batched, every pixel has the bits of the one traced a ray at a
    /// time, in scenes that draw random numbers and trace rays beyond the
    /// camera's: area lights, several camera samples per pixel, glossy
    /// reflection, motion blur over moving layers, transparency; at the
    /// scene's own samples per pixel, at 3 (no divisor of a batch) and at
    /// 33 (a pixel more than a batch). The width is no multiple of any
    /// batch, so rows end on part batches.
    #[test]
    fn batched_rows_give_the_pixels_traced_one_at_a_time() {
        for name in [
            "cornell-area",
            "cornell-sampled",
            "cornell-glossy",
            "motion-blur",
            "cornell-transparent",
        ] {
            let scene = scene::load(name).unwrap();
            let trees: Vec<WideBvh> = scene.meshes().into_iter().map(WideBvh::build).collect();
            let layers: Vec<&WideBvh> = trees.iter().collect();
            for samples_per_pixel in [None, Some(3), Some(33)] {
                let settings = RenderSettings {
                    samples_per_pixel,
                    ..RenderSettings::square(21)
                };
                let renderer = Renderer::new(&scene, &layers, &settings);
                let image = renderer.render_radiance();
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                for y in 0..settings.height {
                    for x in 0..settings.width {
                        assert_eq!(
                            bits(image.get(x, y)),
                            bits(renderer.pixel(x, y)),
                            "{name} at {samples_per_pixel:?} samples, ({x}, {y})"
                        );
                    }
                }
            }
        }
    }
}

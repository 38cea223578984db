//! The order an image's camera rays are traced in: a row's camera samples
//! a batch at a time, the closest-hit queries of the batch's camera rays
//! asked one after another, and only then each sample shaded (its shadow
//! rays, reflections and the rest of its path, as
//! [`Renderer::pixel`] traces them).
//!
//! Asked one by one among the shading, each query waits for the shading
//! before it; asked back to back, a processor starts the next query before
//! the last has finished, as wavefront renderers order their work on GPUs
//! (Laine, Karras and Aila, "Megakernels Considered Harmful: Wavefront
//! Path Tracing on GPUs", HPG 2013). The queries, their answers and the
//! order of every addition are those of [`Renderer::pixel`], so the
//! pixels are the same bits.

use super::Renderer;
use super::debug::ray_paths::RayKind;
use crate::trace::Intersector;
use glam::Vec3;

/// Camera samples per batch, as many whole pixels as fit (one pixel
/// whose samples are more is a batch of its own): with 8, 16, 32 or 64
/// the Cornell box's and the monkey's renders took the same time within
/// 2% (three runs each, one thread, Xeon), so the batch is kept small.
const BATCH_SAMPLES: usize = 32;

impl<I: Intersector + ?Sized> Renderer<'_, I> {
    /// Fills `row`, the pixels of image row `y`, batch by batch.
    pub(super) fn fill_row(&self, y: u32, row: &mut [Vec3]) {
        let count = self.passes.samples_per_pixel;
        let pixels_per_batch = (BATCH_SAMPLES / count as usize).max(1);
        let mut samples = Vec::with_capacity(pixels_per_batch * count as usize);
        let mut hits = Vec::with_capacity(samples.capacity());
        let firsts = (0..).step_by(pixels_per_batch);
        for (pixels, first) in row.chunks_mut(pixels_per_batch).zip(firsts) {
            samples.clear();
            for x in first..first + pixels.len() as u32 {
                for sample in 0..count {
                    samples.push(self.camera_sample(x, y, sample));
                }
            }
            hits.clear();
            hits.extend(
                samples
                    .iter()
                    .map(|(ray, state)| self.closest_hit(ray, state.time)),
            );
            let per_pixel = samples
                .chunks_mut(count as usize)
                .zip(hits.chunks(count as usize));
            for (pixel, (samples, hits)) in pixels.iter_mut().zip(per_pixel) {
                let sum: Vec3 = samples
                    .iter_mut()
                    .zip(hits)
                    .map(|((ray, state), hit)| self.shade(ray, *hit, RayKind::Primary, 0, state))
                    .sum();
                *pixel = sum / count as f32;
            }
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

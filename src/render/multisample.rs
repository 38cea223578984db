//! Several camera rays per pixel at jittered positions (stratified
//! sampling, Cook 1986, or independent ones, as the render's [`Sampler`]
//! says), averaged with equal weights (a box filter).

use super::sampling::{SampleStream, Sampler};
use glam::Vec2;

/// Where camera sample `index` of `count` falls inside its pixel, as an
/// offset in [0, 1)² from the pixel's corner.
pub fn subpixel_offset(
    index: u32,
    count: u32,
    sampler: Sampler,
    stream: &mut SampleStream,
) -> Vec2 {
    sampler.sample_2d(index, count, stream)
}

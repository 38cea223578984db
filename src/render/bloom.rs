//! Bloom, a post-process: pixels whose luminance (Rec. 709 weights) exceeds
//! a threshold are blurred with a separable box or Gaussian filter, and the
//! blur, scaled by a strength, is added back to the image. At the borders
//! the filter is renormalized over the pixels inside the image.

use super::image::Image;
use crate::scene::{BloomFilter, BloomParams};
use glam::Vec3;

/// Rec. 709 luminance of a linear RGB value.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Whether a pixel takes part in the bloom.
pub fn is_bright(c: Vec3, params: &BloomParams) -> bool {
    luminance(c) > params.threshold
}

/// The image with its bloom added.
pub fn apply(image: &Image, params: &BloomParams) -> Image {
    let bright = Image {
        pixels: image
            .pixels
            .iter()
            .map(|&c| if is_bright(c, params) { c } else { Vec3::ZERO })
            .collect(),
        ..image.clone()
    };
    let weights = kernel(params);
    let blurred = blur_columns(&blur_rows(&bright, &weights), &weights);
    Image {
        pixels: image
            .pixels
            .iter()
            .zip(&blurred.pixels)
            .map(|(&c, &b)| c + params.strength * b)
            .collect(),
        ..image.clone()
    }
}

/// Weights for offsets `-radius ..= radius`.
fn kernel(params: &BloomParams) -> Vec<f32> {
    let r = params.radius as i64;
    let sigma = (params.radius as f32 / 2.0).max(0.5);
    (-r..=r)
        .map(|i| match params.filter {
            BloomFilter::Box => 1.0,
            BloomFilter::Gaussian => (-0.5 * (i as f32 / sigma).powi(2)).exp(),
        })
        .collect()
}

fn blur_rows(image: &Image, weights: &[f32]) -> Image {
    blur(image, weights, |x, y| (x, y), image.width, image.height)
}

fn blur_columns(image: &Image, weights: &[f32]) -> Image {
    blur(image, weights, |x, y| (y, x), image.height, image.width)
}

/// Blurs along lines of `length` pixels; `at(i, line)` gives the image
/// coordinates of position `i` on a line.
fn blur(
    image: &Image,
    weights: &[f32],
    at: impl Fn(u32, u32) -> (u32, u32),
    length: u32,
    lines: u32,
) -> Image {
    let r = (weights.len() / 2) as i64;
    let mut out = image.clone();
    for line in 0..lines {
        for i in 0..length {
            let (mut sum, mut total) = (Vec3::ZERO, 0.0);
            for (k, &w) in weights.iter().enumerate() {
                let j = i as i64 + k as i64 - r;
                if (0..length as i64).contains(&j) {
                    let (x, y) = at(j as u32, line);
                    sum += w * image.get(x, y);
                    total += w;
                }
            }
            let (x, y) = at(i, line);
            out.pixels[(y * image.width + x) as usize] = sum / total;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(filter: BloomFilter) -> BloomParams {
        BloomParams {
            threshold: 1.0,
            radius: 2,
            filter,
            strength: 1.0,
        }
    }

    #[test]
    fn a_bright_pixel_spreads_and_dim_ones_do_not() {
        for filter in [BloomFilter::Box, BloomFilter::Gaussian] {
            let mut image = Image::new(9, 9);
            image.pixels[4 * 9 + 4] = Vec3::splat(10.0);
            image.pixels[0] = Vec3::splat(0.5);
            let out = apply(&image, &params(filter));
            assert!(out.get(5, 4).x > 0.0 && out.get(4, 6).x > 0.0);
            assert_eq!(out.get(7, 4), Vec3::ZERO, "beyond the radius");
            assert_eq!(out.get(0, 0), Vec3::splat(0.5), "dim pixels are unchanged");
            // Far from the borders the filter keeps the bright energy.
            let added: f32 = out
                .pixels
                .iter()
                .zip(&image.pixels)
                .map(|(a, b)| a.x - b.x)
                .sum();
            assert!((added - 10.0).abs() < 1e-4, "{filter:?}: {added}");
        }
    }
}

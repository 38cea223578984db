//! Image error against a reference: relMSE, the relative mean squared error
//! of the denoising and adaptive-sampling literature (Rousselle, Knaus,
//! Zwicker 2011, "Adaptive sampling and reconstruction using greedy error
//! minimization"), on the linear values; and mean FLIP (Andersson et al.
//! 2020, "FLIP: A Difference Evaluator for Alternating Images"), the
//! perceived difference, on the images as a viewer sees them.

use crate::render::image::Image;
use anyhow::ensure;

/// The constant in relMSE's denominator, so that black reference pixels do
/// not divide by zero.
pub const REL_MSE_EPSILON: f64 = 0.01;

/// relMSE of `image` against `reference`: the mean over pixels and
/// channels of `(I − R)² / (R² + 0.01)`, in f64.
pub fn rel_mse(image: &Image, reference: &Image) -> anyhow::Result<f64> {
    same_size(image, reference)?;
    let sum: f64 = image
        .pixels
        .iter()
        .zip(&reference.pixels)
        .flat_map(|(i, r)| i.to_array().into_iter().zip(r.to_array()))
        .map(|(i, r)| {
            let (i, r) = (i as f64, r as f64);
            (i - r).powi(2) / (r * r + REL_MSE_EPSILON)
        })
        .sum();
    Ok(sum / (3 * image.pixels.len()) as f64)
}

/// Mean FLIP of `image` against `reference`, in [0, 1]. FLIP's LDR mode
/// compares what a display shows, so both images are first tone-mapped
/// the way their PNGs are ([`Image::to_srgb8`]): each linear channel
/// clamped to [0, 1], encoded with the sRGB transfer curve and rounded to
/// 8 bits. Pixels are seen at FLIP's default 67 pixels per degree (a 0.7 m
/// wide 4K display viewed from 0.7 m). The mean is over the per-pixel error
/// map, in f64.
pub fn mean_flip(image: &Image, reference: &Image) -> anyhow::Result<f64> {
    same_size(image, reference)?;
    let to_flip = |i: &Image| nv_flip::FlipImageRgb8::with_data(i.width, i.height, &i.to_srgb8());
    let errors = nv_flip::flip(
        to_flip(reference),
        to_flip(image),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec();
    Ok(errors.iter().map(|&e| e as f64).sum::<f64>() / errors.len() as f64)
}

fn same_size(image: &Image, reference: &Image) -> anyhow::Result<()> {
    ensure!(
        (image.width, image.height) == (reference.width, reference.height),
        "a {}×{} image cannot be compared with a {}×{} reference",
        image.width,
        image.height,
        reference.width,
        reference.height
    );
    ensure!(!image.pixels.is_empty(), "the images have no pixels");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::image::decode_srgb;
    use glam::Vec3;

    fn uniform(value: Vec3) -> Image {
        Image {
            width: 16,
            height: 16,
            pixels: vec![value; 256],
        }
    }

    #[test]
    fn rel_mse_is_zero_for_identical_images_and_known_for_an_offset() {
        let mut reference = uniform(Vec3::splat(0.1));
        reference.pixels[7] = Vec3::new(0.5, 0.0, 2.0);
        assert_eq!(rel_mse(&reference, &reference).unwrap(), 0.0);
        // R = 0.1 and I = R + 0.1 everywhere: 0.01 / (0.01 + 0.01) = 1/2.
        let reference = uniform(Vec3::splat(0.1));
        let brighter = uniform(Vec3::splat(0.2));
        assert!((rel_mse(&brighter, &reference).unwrap() - 0.5).abs() < 1e-6);
        // R = 0, I = 0.1 in one channel of one pixel: 0.01 / 0.01 / (3·256).
        let black = uniform(Vec3::ZERO);
        let mut speck = black.clone();
        speck.pixels[3].y = 0.1;
        let expected = 1.0 / (3.0 * 256.0);
        assert!((rel_mse(&speck, &black).unwrap() - expected).abs() < 1e-9);
        // Relative: the same offset on a ten times brighter reference
        // counts about a hundred times less.
        let bright = uniform(Vec3::splat(1.0));
        let offset = uniform(Vec3::splat(1.1));
        let relative = rel_mse(&offset, &bright).unwrap();
        assert!((relative - 0.01 / 1.01).abs() < 1e-6, "{relative}");
    }

    #[test]
    fn images_of_different_sizes_are_an_error() {
        let small = Image::new(2, 2);
        let error = rel_mse(&small, &Image::new(2, 3)).unwrap_err();
        assert_eq!(
            error.to_string(),
            "a 2×2 image cannot be compared with a 2×3 reference"
        );
        assert!(mean_flip(&small, &Image::new(3, 2)).is_err());
    }

    /// FLIP's colour error between two uniform greys, by hand from the
    /// paper's colour pipeline: on flat images the spatial filters change nothing and the
    /// feature (edge and point) differences are 0, so FLIP is the colour
    /// difference alone. Neutral greys have a* = b* = 0, so the HyAB
    /// distance is |ΔL*|; raised to q_c = 0.7 and mapped against
    /// c_max = HyAB(Hunt(green), Hunt(blue))^0.7 with p_c = 0.4, p_t = 0.95.
    fn flip_of_greys(a: f64, b: f64) -> f64 {
        let lightness = |y: f64| {
            let f = if y > (6.0f64 / 29.0).powi(3) {
                y.cbrt()
            } else {
                y / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
            };
            116.0 * f - 16.0
        };
        // L*a*b* of linear sRGB primaries (D65 white = XYZ of (1, 1, 1)),
        // with the Hunt adjustment a*, b* × L*/100.
        let hunt_lab = |rgb: [f64; 3]| {
            let m = [
                [0.4124564, 0.3575761, 0.1804375],
                [0.2126729, 0.7151522, 0.0721750],
                [0.0193339, 0.1191920, 0.9503041],
            ];
            let xyz = m.map(|row| row.iter().zip(rgb).map(|(c, v)| c * v).sum::<f64>());
            let white = m.map(|row| row.iter().sum::<f64>());
            let f = |i: usize| {
                let t = xyz[i] / white[i];
                if t > (6.0f64 / 29.0).powi(3) {
                    t.cbrt()
                } else {
                    t / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
                }
            };
            let l = 116.0 * f(1) - 16.0;
            let (a, b) = (500.0 * (f(0) - f(1)), 200.0 * (f(1) - f(2)));
            [l, a * l / 100.0, b * l / 100.0]
        };
        let (green, blue) = (hunt_lab([0.0, 1.0, 0.0]), hunt_lab([0.0, 0.0, 1.0]));
        let hyab = (green[0] - blue[0]).abs() + (green[1] - blue[1]).hypot(green[2] - blue[2]);
        let c_max = hyab.powf(0.7);
        let error = (lightness(a) - lightness(b)).abs().powf(0.7);
        let (p_c, p_t) = (0.4, 0.95);
        if error < p_c * c_max {
            p_t / (p_c * c_max) * error
        } else {
            p_t + (error - p_c * c_max) / (c_max - p_c * c_max) * (1.0 - p_t)
        }
    }

    #[test]
    fn flip_is_zero_for_identical_images_and_known_for_uniform_greys() {
        let mut reference = uniform(Vec3::splat(0.2));
        reference.pixels[40] = Vec3::new(0.9, 0.1, 0.3);
        assert_eq!(mean_flip(&reference, &reference).unwrap(), 0.0);
        // Black against white, and against an 8-bit grey of 64/255 (which
        // the sRGB encoding keeps exactly). FLIP computes in f32 with its own
        // rounding of the sRGB-to-XYZ matrix: the two agree to 2e-5.
        let black = uniform(Vec3::ZERO);
        let white = uniform(Vec3::ONE);
        let grey = decode_srgb(64.0 / 255.0);
        for (other, y) in [(white, 1.0), (uniform(Vec3::splat(grey)), grey as f64)] {
            let by_hand = flip_of_greys(0.0, y);
            let flip = mean_flip(&other, &black).unwrap();
            assert!((flip - by_hand).abs() < 2e-5, "{flip} vs {by_hand}");
        }
    }
}

//! Glossy reflection: reflection rays spread around the mirror direction
//! in a Phong lobe of density `(n+1)/(2π)·cos^n α` over the hemisphere
//! around the mirror direction (α is the angle from it; Lafortune & Willems
//! 1994, "Using the modified Phong reflectance model for physically based
//! rendering"), with the exponent from a roughness r as n = 2/r² − 2 (the
//! Phong–Beckmann correspondence of Walter et al. 2007, "Microfacet models
//! for refraction through rough surfaces", §5.2).
//!
//! The reflected colour is the lobe's average of the light arriving from
//! above the surface, `∫ p(ω)·L(ω)·[ω above] dω`. Directions are drawn from
//! the lobe itself, so each sample's weight is `p/p = 1` where it leaves
//! above the surface; the part of the lobe below the surface (near grazing
//! it can be half of it) would leave through the surface and reflects
//! nothing, so a sample drawn there adds black and still counts in the
//! average. That keeps the estimate unbiased with a fixed sample count
//! (rather than resampling until a sample lands above, which would need the
//! lobe's mass above the surface as a weight).

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, TAU};

/// The Phong exponent of a roughness in (0, 1].
pub fn phong_exponent(roughness: f32) -> f32 {
    2.0 / (roughness * roughness) - 2.0
}

/// A direction of the lobe of exponent `exponent` around the unit vector
/// `mirror`, from a uniform point `xi` of the unit square: the inverse of
/// the lobe's distribution in (cos α, φ), so its density is [`lobe_pdf`].
pub fn sample_lobe(mirror: Vec3, exponent: f32, xi: Vec2) -> Vec3 {
    let cos_alpha = xi.x.powf(1.0 / (exponent + 1.0));
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let phi = TAU * xi.y;
    let (tangent, bitangent) = mirror.any_orthonormal_pair();
    cos_alpha * mirror + sin_alpha * (phi.cos() * tangent + phi.sin() * bitangent)
}

/// The density of [`sample_lobe`] per unit solid angle at the unit
/// direction `dir`: `(n+1)/(2π)·cos^n α` within 90° of `mirror`, 0 beyond.
pub fn lobe_pdf(mirror: Vec3, exponent: f32, dir: Vec3) -> f32 {
    let cos_alpha = mirror.dot(dir);
    if cos_alpha <= 0.0 {
        return 0.0;
    }
    (exponent + 1.0) * 0.5 * FRAC_1_PI * cos_alpha.powf(exponent)
}

/// The reflection direction of lobe sample `xi`, or `None` where the lobe
/// lies below the surface of (geometric) normal `normal`: such a sample
/// reflects no light (see the module's documentation).
pub fn reflect(mirror: Vec3, normal: Vec3, exponent: f32, xi: Vec2) -> Option<Vec3> {
    let dir = sample_lobe(mirror, exponent, xi);
    (dir.dot(normal) > 0.0).then_some(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lobe_narrows_as_roughness_falls() {
        let spread = |roughness: f32| {
            let n = phong_exponent(roughness);
            (0..64)
                .map(|i| {
                    let xi = Vec2::new((i as f32 + 0.5) / 64.0, (i * 7 % 64) as f32 / 64.0);
                    sample_lobe(Vec3::Z, n, xi).dot(Vec3::Z)
                })
                .fold(1.0f32, f32::min)
        };
        assert!(spread(0.05) > spread(0.3));
        assert!(spread(0.05) > 0.99);
        assert_eq!(phong_exponent(1.0), 0.0);
    }

    #[test]
    fn samples_below_the_surface_reflect_nothing_and_the_others_keep_their_direction() {
        let normal = Vec3::Y;
        let mirror = Vec3::new(1.0, 0.05, 0.0).normalize();
        let (mut above, mut below) = (0, 0);
        for i in 0..256 {
            let xi = Vec2::new((i % 16) as f32 / 16.0, (i / 16) as f32 / 16.0);
            let dir = sample_lobe(mirror, 2.0, xi);
            match reflect(mirror, normal, 2.0, xi) {
                Some(d) => {
                    assert_eq!(d, dir);
                    assert!(d.dot(normal) > 0.0);
                    above += 1;
                }
                None => {
                    assert!(dir.dot(normal) <= 0.0);
                    below += 1;
                }
            }
        }
        // A wide lobe 3° above grazing: close to half of it is below.
        assert!(above > 0 && below > 64, "{above} above, {below} below");
    }

    #[test]
    fn the_density_integrates_to_one_over_the_sphere() {
        let mirror = Vec3::new(0.3, 0.4, 0.5).normalize();
        for exponent in [0.0, 2.0, 137.0] {
            // Midpoint rule in (cos θ, φ) about the mirror direction.
            let (rows, columns) = (4000, 64);
            let mut sum = 0.0f64;
            let (t, b) = mirror.any_orthonormal_pair();
            for i in 0..rows {
                let cos_theta = 1.0 - 2.0 * (i as f32 + 0.5) / rows as f32;
                let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
                for j in 0..columns {
                    let phi = TAU * (j as f32 + 0.5) / columns as f32;
                    let dir = cos_theta * mirror + sin_theta * (phi.cos() * t + phi.sin() * b);
                    sum += lobe_pdf(mirror, exponent, dir) as f64;
                }
            }
            let integral = sum * 2.0 * std::f64::consts::TAU / (rows * columns) as f64;
            assert!((integral - 1.0).abs() < 1e-3, "n = {exponent}: {integral}");
        }
    }
}

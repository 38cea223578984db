//! Glossy reflection: reflection rays spread around the mirror direction
//! in a Phong lobe, `pdf ∝ cos^n α` (Lafortune & Willems 1994, "Using the
//! modified Phong reflectance model for physically based rendering"), with
//! the exponent from a roughness r as n = 2/r² − 2 (the Phong–Beckmann
//! correspondence of Walter et al. 2007, "Microfacet models for refraction
//! through rough surfaces", §5.2). The lobe is importance-sampled, so the
//! reflected colour is the plain average of the samples.

use glam::{Vec2, Vec3};

/// The Phong exponent of a roughness in (0, 1].
pub fn phong_exponent(roughness: f32) -> f32 {
    2.0 / (roughness * roughness) - 2.0
}

/// A direction in the Phong lobe of exponent `exponent` around the unit
/// vector `mirror`, from a uniform point `xi` of the unit square. A
/// direction under the surface (normal `normal`) falls back to the mirror
/// direction, so no sample leaves through the surface.
pub fn perturb(mirror: Vec3, normal: Vec3, exponent: f32, xi: Vec2) -> Vec3 {
    let cos_alpha = xi.x.powf(1.0 / (exponent + 1.0));
    let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * xi.y;
    let (tangent, bitangent) = mirror.any_orthonormal_pair();
    let dir = cos_alpha * mirror + sin_alpha * (phi.cos() * tangent + phi.sin() * bitangent);
    if dir.dot(normal) > 0.0 { dir } else { mirror }
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
                    perturb(Vec3::Z, Vec3::Z, n, xi).dot(Vec3::Z)
                })
                .fold(1.0f32, f32::min)
        };
        assert!(spread(0.05) > spread(0.3));
        assert!(spread(0.05) > 0.99);
        assert_eq!(phong_exponent(1.0), 0.0);
    }

    #[test]
    fn never_leaves_below_the_surface() {
        let normal = Vec3::Y;
        let mirror = Vec3::new(1.0, 0.05, 0.0).normalize();
        for i in 0..256 {
            let xi = Vec2::new((i % 16) as f32 / 16.0, (i / 16) as f32 / 16.0);
            assert!(perturb(mirror, normal, 2.0, xi).dot(normal) > 0.0);
        }
    }
}

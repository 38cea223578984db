//! Area lights: segment and parallelogram lights sampled at N points
//! (Cook, Porter, Carpenter 1984, "Distributed ray tracing"), placed by the
//! render's [`Sampler`] over the light's parameter domain; the fraction of
//! samples a point sees gives soft shadows.
//!
//! A segment's sample is an isotropic point of intensity `colour / N`, the
//! colour interpolated linearly along it. A parallelogram's sample is a
//! Lambertian patch of area `A / N` and radiance `L` (interpolated
//! bilinearly over the corners): it sends intensity `L·(A/N)·cos θ` at the
//! angle θ from the light's normal, and nothing to the side it does not
//! emit on. With points uniform over the light (density `1/A`), the sum of
//! the samples' contributions `L·(A/N)·cos θ·cos θ'/r²` is the unbiased
//! estimate of the light's irradiance `∫ L cos θ cos θ' / r² dA` (Shirley,
//! Wang, Zimmerman 1996, "Monte Carlo techniques for direct lighting
//! calculations": luminaires sampled uniformly by area).

use super::sampling::{SampleStream, Sampler};
use crate::scene::Light;
use glam::Vec3;

/// A point on a light, the intensity it carries and how that spreads over
/// directions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    pub position: Vec3,
    /// The intensity sent along the emitter's normal (every direction, for
    /// an isotropic one).
    pub intensity: Vec3,
    pub emission: Emission,
}

/// How a light sample's intensity depends on the direction it leaves in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Emission {
    /// The same in every direction: points and segments.
    Isotropic,
    /// Lambertian, `cos θ` from the unit `normal`; nothing behind it unless
    /// `two_sided`, which emits `|cos θ|` on both sides.
    Cosine { normal: Vec3, two_sided: bool },
}

impl LightSample {
    /// The intensity the sample sends towards `point`, or `None` when
    /// `point` is behind its emitting side (or in its plane), so that it
    /// gets no light and needs no shadow ray.
    pub fn intensity_towards(&self, point: Vec3) -> Option<Vec3> {
        match self.emission {
            Emission::Isotropic => Some(self.intensity),
            Emission::Cosine { normal, two_sided } => {
                let cos = normal.dot((point - self.position).normalize_or_zero());
                let cos = if two_sided { cos.abs() } else { cos };
                (cos > 0.0).then(|| cos * self.intensity)
            }
        }
    }
}

/// Sample `index` of `count` of `light`, placed by `sampler`: the light's
/// own point (and full colour) for a point light.
pub fn sample(
    light: &Light,
    index: u32,
    count: u32,
    sampler: Sampler,
    stream: &mut SampleStream,
) -> LightSample {
    match light {
        Light::Point { position, color } => LightSample {
            position: *position,
            intensity: *color,
            emission: Emission::Isotropic,
        },
        Light::Segment { a, b, colors } => {
            let s = sampler.sample_1d(index, count, stream);
            LightSample {
                position: a.lerp(*b, s),
                intensity: colors[0].lerp(colors[1], s) / count as f32,
                emission: Emission::Isotropic,
            }
        }
        Light::Parallelogram {
            corner,
            edge_u,
            edge_v,
            colors,
            ..
        } => {
            let st = sampler.sample_2d(index, count, stream);
            let bottom = colors[0].lerp(colors[1], st.x);
            let top = colors[3].lerp(colors[2], st.x);
            let radiance = bottom.lerp(top, st.y);
            LightSample {
                position: *corner + st.x * *edge_u + st.y * *edge_v,
                intensity: radiance * (light.area() / count as f32),
                emission: emission(light),
            }
        }
    }
}

/// The whole light as one sample at its centre, for renders that do not
/// sample area lights: a segment is a point of its mean colour, a
/// parallelogram a Lambertian patch of its mean radiance and whole area.
pub fn whole(light: &Light) -> LightSample {
    let intensity = match light {
        Light::Parallelogram { .. } => light.mean_color() * light.area(),
        _ => light.mean_color(),
    };
    LightSample {
        position: light.representative_point(),
        intensity,
        emission: emission(light),
    }
}

/// Lambertian about the normal for a parallelogram, isotropic otherwise.
fn emission(light: &Light) -> Emission {
    match (light, light.normal()) {
        (Light::Parallelogram { two_sided, .. }, Some(normal)) => Emission::Cosine {
            normal,
            two_sided: *two_sided,
        },
        _ => Emission::Isotropic,
    }
}

/// How many samples a light takes: one for a point.
pub fn sample_count(light: &Light, light_samples: u32) -> u32 {
    match light {
        Light::Point { .. } => 1,
        _ => light_samples,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(two_sided: bool) -> Light {
        // x × z = -y: the emitting side faces down.
        Light::Parallelogram {
            corner: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: Vec3::Z,
            colors: [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO],
            two_sided,
        }
    }

    #[test]
    fn corner_colours_interpolate_and_intensities_sum_to_radiance_times_area() {
        let light = Light::Parallelogram {
            corner: Vec3::ZERO,
            edge_u: 2.0 * Vec3::X,
            edge_v: Vec3::Z,
            colors: [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO],
            two_sided: false,
        };
        let mut stream = SampleStream::new(1, 0, 0);
        let n = 4096;
        let samples: Vec<LightSample> = (0..n)
            .map(|i| sample(&light, i, n, Sampler::Stratified, &mut stream))
            .collect();
        let total: Vec3 = samples.iter().map(|s| s.intensity).sum();
        // Mean radiance 1/4 per channel over an area of 2.
        assert!(
            (total - Vec3::splat(0.5)).abs().max_element() < 1e-3,
            "{total}"
        );
        for s in &samples {
            let (u, v) = (s.position.x / 2.0, s.position.z);
            let radiance = Vec3::new((1.0 - u) * (1.0 - v), u * (1.0 - v), u * v);
            assert!(
                (s.intensity - radiance * 2.0 / n as f32)
                    .abs()
                    .max_element()
                    < 1e-6
            );
        }
        assert_eq!(whole(&light).intensity, Vec3::splat(0.5));
    }

    #[test]
    fn a_one_sided_light_sends_nothing_behind_it_and_a_two_sided_one_does() {
        let mut stream = SampleStream::new(1, 0, 0);
        for two_sided in [false, true] {
            let s = sample(&quad(two_sided), 0, 1, Sampler::Stratified, &mut stream);
            let below = s.position + Vec3::new(0.3, -2.0, 0.1);
            let above = s.position + Vec3::new(0.3, 2.0, 0.1);
            let cos = 2.0 / Vec3::new(0.3, 2.0, 0.1).length();
            let lit = s.intensity_towards(below).unwrap();
            assert!((lit - cos * s.intensity).abs().max_element() < 1e-6);
            assert_eq!(s.intensity_towards(above).is_some(), two_sided);
            // Grazing: in the light's own plane nothing is emitted.
            assert_eq!(s.intensity_towards(s.position + Vec3::X), None);
        }
        let segment = Light::Segment {
            a: Vec3::ZERO,
            b: Vec3::X,
            colors: [Vec3::ONE; 2],
        };
        let s = sample(&segment, 0, 2, Sampler::Stratified, &mut stream);
        assert_eq!(s.intensity_towards(Vec3::Y), Some(Vec3::splat(0.5)));
        assert_eq!(s.intensity_towards(Vec3::NEG_Y), Some(Vec3::splat(0.5)));
    }
}

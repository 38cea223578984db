//! Area lights: segment and parallelogram lights sampled at N stratified,
//! jittered points (Cook, Porter, Carpenter 1984, "Distributed ray
//! tracing"), each an isotropic point of intensity `colour / N` with the
//! colour interpolated over the light (linearly along a segment,
//! bilinearly over a parallelogram's corners). The fraction of samples a
//! point sees gives soft shadows.

use super::sampling::{SampleStream, stratified_1d, stratified_2d};
use crate::scene::Light;
use glam::Vec3;

/// A point on a light and the intensity it carries.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    pub position: Vec3,
    pub intensity: Vec3,
}

/// Sample `index` of `count` of `light`: the light's own point (and full
/// colour) for a point light.
pub fn sample(light: &Light, index: u32, count: u32, stream: &mut SampleStream) -> LightSample {
    match light {
        Light::Point { position, color } => LightSample {
            position: *position,
            intensity: *color,
        },
        Light::Segment { a, b, colors } => {
            let s = stratified_1d(index, count, stream.next_1d());
            LightSample {
                position: a.lerp(*b, s),
                intensity: colors[0].lerp(colors[1], s) / count as f32,
            }
        }
        Light::Parallelogram {
            corner,
            edge_u,
            edge_v,
            colors,
        } => {
            let st = stratified_2d(index, count, stream.next_2d());
            let bottom = colors[0].lerp(colors[1], st.x);
            let top = colors[3].lerp(colors[2], st.x);
            LightSample {
                position: *corner + st.x * *edge_u + st.y * *edge_v,
                intensity: bottom.lerp(top, st.y) / count as f32,
            }
        }
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

    #[test]
    fn corner_colours_interpolate_and_intensities_sum_to_the_mean() {
        let light = Light::Parallelogram {
            corner: Vec3::ZERO,
            edge_u: Vec3::X,
            edge_v: Vec3::Z,
            colors: [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO],
        };
        let mut stream = SampleStream::new(1, 0, 0);
        let n = 4096;
        let samples: Vec<LightSample> = (0..n).map(|i| sample(&light, i, n, &mut stream)).collect();
        let total: Vec3 = samples.iter().map(|s| s.intensity).sum();
        assert!(
            (total - Vec3::splat(0.25)).abs().max_element() < 1e-3,
            "{total}"
        );
        for s in &samples {
            let (u, v) = (s.position.x, s.position.z);
            let expected = Vec3::new((1.0 - u) * (1.0 - v), u * (1.0 - v), u * v) / n as f32;
            assert!((s.intensity - expected).abs().max_element() < 1e-6);
        }
    }
}

//! Where a secondary ray starts, so that it never re-hits the surface it
//! leaves.
//!
//! Method: Wächter & Binder, "A Fast and Robust Method for Avoiding
//! Self-Intersection", Ray Tracing Gems (2019), ch. 6. The hit point is moved
//! along the geometric normal by a fixed number of integer ulps per
//! component, so the offset scales with the magnitude of the coordinates
//! (a fixed epsilon is too small far from the origin and too large near it);
//! close to the origin, where ulps become tiny, a small fixed offset is
//! added instead. No epsilon on `tnear` is needed after this: secondary rays
//! start at `tnear = 0`.

use glam::Vec3;

/// Below this magnitude a component is offset by a fixed amount.
const ORIGIN_REGION: f32 = 1.0 / 32.0;
/// The fixed offset used near the origin, per unit of normal.
const FLOAT_SCALE: f32 = 1.0 / 65536.0;
/// Integer ulps moved per unit of normal.
const INT_SCALE: f32 = 256.0;

/// Moves `point` off its surface to the side `normal` points to.
///
/// `normal` is the geometric normal oriented towards the side the new ray
/// leaves into; it need not be normalized but should be of unit order.
pub fn offset_ray_origin(point: Vec3, normal: Vec3) -> Vec3 {
    let n = normal.normalize_or_zero();
    Vec3::from_array(std::array::from_fn(|axis| {
        offset_component(point[axis], n[axis])
    }))
}

fn offset_component(p: f32, n: f32) -> f32 {
    if p.abs() < ORIGIN_REGION {
        return p + FLOAT_SCALE * n;
    }
    let ulps = (INT_SCALE * n) as i32;
    // Moving away from zero increases the bit pattern of a positive float
    // and of a negative one alike, so the step's sign follows p's sign.
    let step = if p < 0.0 { -ulps } else { ulps };
    f32::from_bits((p.to_bits() as i32).wrapping_add(step) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moves_to_the_normal_side_at_every_scale() {
        for scale in [1e-3f32, 0.5, 1.0, 1e3, 1e6] {
            for sign in [1.0f32, -1.0] {
                let p = Vec3::new(sign * scale, 0.25 * scale, -scale);
                for n in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Z, Vec3::ONE.normalize()] {
                    let q = offset_ray_origin(p, n);
                    assert!((q - p).dot(n) > 0.0, "p={p} n={n} q={q}");
                }
            }
        }
    }

    #[test]
    fn offset_is_relative_to_magnitude() {
        let near = offset_ray_origin(Vec3::splat(1.0), Vec3::Z).z - 1.0;
        let far = offset_ray_origin(Vec3::splat(1e6), Vec3::Z).z - 1e6;
        assert!(near > 0.0 && near < 1e-4, "near offset {near}");
        assert!(far > 1e-2 && far < 100.0, "far offset {far}");
    }
}

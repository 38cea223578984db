//! Recursive mirror reflection (Whitted 1980): a surface with mirror
//! reflectance `m` shows `(1 - m)·local + m·reflected`, per channel, down to
//! a maximum depth. Reflection rays start at the offset origin of
//! [`crate::geometry::offset`], so a mirror never reflects itself.

use glam::Vec3;

/// Blends the local colour with the reflected one by the mirror reflectance.
pub fn blend(local: Vec3, mirror: Vec3, reflected: Vec3) -> Vec3 {
    (Vec3::ONE - mirror) * local + mirror * reflected
}

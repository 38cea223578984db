//! The conservative ray/box slab test.
//!
//! The slab distances are computed with the reciprocal direction, each with
//! at most three roundings, so the far distance is scaled by `1 + 2γ(3)`
//! (and the near one by `1 - 2γ(3)`)
//! (Ize, "Robust BVH Ray Traversal", JCGT 2(2), 2013, the box test Woop et
//! al. 2013 pair with the watertight triangle test): a box the exact ray
//! touches is never rejected.

use super::Node;
use crate::geometry::Ray;
use glam::{BVec3, Vec3};

/// γ(n) = nε / (1 - nε) with ε the f32 unit roundoff (pbrt's bound on n
/// roundings).
const fn gamma(n: f32) -> f32 {
    let e = f32::EPSILON * 0.5;
    n * e / (1.0 - n * e)
}

pub(super) const GROW: f32 = 1.0 + 2.0 * gamma(3.0);
pub(super) const SHRINK: f32 = 1.0 - 2.0 * gamma(3.0);

/// A ray prepared for box tests.
#[derive(Clone, Copy, Debug)]
pub(super) struct RayBox {
    origin: Vec3,
    /// `1 / dir`; a zero component gives an infinity of the zero's sign.
    inv_dir: Vec3,
    /// Per axis, whether the box's max plane is met first.
    negative: BVec3,
}

impl RayBox {
    pub fn new(ray: &Ray) -> Self {
        let inv_dir = ray.dir.recip();
        Self {
            origin: ray.origin,
            inv_dir,
            negative: inv_dir.cmplt(Vec3::ZERO),
        }
    }

    /// Where the ray enters `node`'s box if its `[tnear, tfar]` meets the box.
    ///
    /// With a zero direction component the ray lies in the slab for all `t`
    /// or for none; a ray in the slab's boundary plane gives `0 · ∞ = NaN`,
    /// which `f32::max`/`f32::min` ignore, so such a slab never rejects.
    pub fn entry(&self, node: &Node, tnear: f32, tfar: f32) -> Option<f32> {
        let b = node.bounds();
        let near_plane = Vec3::select(self.negative, b.max, b.min);
        let far_plane = Vec3::select(self.negative, b.min, b.max);
        let near = (near_plane - self.origin) * self.inv_dir;
        let far = (far_plane - self.origin) * self.inv_dir;
        let far = far.x.min(far.y).min(far.z);
        let far = far * if far > 0.0 { GROW } else { SHRINK };
        // The entry distance is pulled back by the same bound, so a box whose
        // exact entry equals the best hit so far is still visited: ties then
        // resolve as in a loop over all triangles.
        let near = near.x.max(near.y).max(near.z);
        let near = near * if near > 0.0 { SHRINK } else { GROW };
        let enter = tnear.max(near);
        let exit = tfar.min(far);
        (enter <= exit).then_some(enter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    fn unit_box() -> Node {
        Node::leaf(
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE,
            },
            0,
            1,
        )
    }

    fn entry(origin: Vec3, dir: Vec3) -> Option<f32> {
        RayBox::new(&Ray::new(origin, dir)).entry(&unit_box(), 0.0, f32::INFINITY)
    }

    /// An exact entry distance of 1, pulled back by the rounding bound.
    const ENTRY_AT_ONE: Option<f32> = Some(SHRINK);

    #[test]
    fn entry_distance_through_the_box() {
        assert_eq!(entry(Vec3::new(-1.0, 0.5, 0.5), Vec3::X), ENTRY_AT_ONE);
        assert_eq!(entry(Vec3::new(2.0, 0.5, 0.5), Vec3::NEG_X), ENTRY_AT_ONE);
        assert_eq!(entry(Vec3::splat(0.5), Vec3::Y), Some(0.0));
        assert_eq!(entry(Vec3::new(-1.0, 2.0, 0.5), Vec3::X), None);
        assert_eq!(entry(Vec3::new(2.0, 0.5, 0.5), Vec3::X), None);
    }

    #[test]
    fn zero_direction_components_on_box_faces() {
        // Along a face or an edge of the box: touching counts.
        for origin in [
            Vec3::new(-1.0, 0.0, 0.5),
            Vec3::new(-1.0, 1.0, 0.5),
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(-1.0, 1.0, 1.0),
        ] {
            assert_eq!(entry(origin, Vec3::X), ENTRY_AT_ONE, "{origin}");
            assert_eq!(
                entry(origin, Vec3::new(1.0, -0.0, -0.0)),
                ENTRY_AT_ONE,
                "{origin}"
            );
        }
        // Parallel and outside.
        assert_eq!(entry(Vec3::new(-1.0, 1.5, 0.5), Vec3::X), None);
        assert_eq!(
            entry(Vec3::new(-1.0, -0.5, 0.5), Vec3::new(1.0, -0.0, 0.0)),
            None
        );
    }

    #[test]
    fn flat_boxes_are_hit() {
        let flat = Node::leaf(
            Aabb {
                min: Vec3::new(0.0, 0.0, 2.0),
                max: Vec3::new(1.0, 1.0, 2.0),
            },
            0,
            1,
        );
        let ray = Ray::new(Vec3::new(0.3, 0.7, 0.0), Vec3::new(0.1, -0.1, 1.0));
        let enter = RayBox::new(&ray)
            .entry(&flat, 0.0, f32::INFINITY)
            .expect("hit");
        assert!((2.0 * SHRINK * SHRINK..=2.0).contains(&enter), "{enter}");
    }

    #[test]
    fn interval_limits_apply() {
        let rb = RayBox::new(&Ray::new(Vec3::new(-1.0, 0.5, 0.5), Vec3::X));
        assert_eq!(rb.entry(&unit_box(), 0.0, 0.5), None);
        assert_eq!(rb.entry(&unit_box(), 0.0, 1.0), ENTRY_AT_ONE);
        assert_eq!(rb.entry(&unit_box(), 2.0, 3.0), Some(2.0));
        assert_eq!(rb.entry(&unit_box(), 2.5, 3.0), None);
    }
}

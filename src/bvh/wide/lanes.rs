//! The two per-node kernels of the traversal, the 4-lane box test and the
//! 4-lane triangle pre-test, as a trait with a portable scalar
//! implementation ([`Scalar`]); `simd.rs` implements the same trait with
//! `std::arch` intrinsics.

use super::node::{TriangleBlock, WIDTH, WideNode};
use crate::bvh::ray_box::{GROW, SHRINK};
use crate::geometry::Ray;
use crate::geometry::triangle::WatertightRay;

/// A ray prepared for the box tests: the planes it meets first and last on
/// each axis are chosen once from the signs of its direction (its octant).
#[derive(Clone, Copy, Debug)]
pub(super) struct RayLanes {
    pub origin: [f32; 3],
    /// `1 / dir`; a zero component gives an infinity of the zero's sign.
    pub inv_dir: [f32; 3],
    /// Per axis, the index in [`WideNode::planes`] of the plane met first.
    pub near: [usize; 3],
    /// The same for the plane met last.
    pub far: [usize; 3],
    pub tnear: f32,
}

impl RayLanes {
    pub fn new(ray: &Ray) -> Self {
        let inv_dir = ray.dir.recip().to_array();
        let negative = inv_dir.map(|d| usize::from(d < 0.0));
        Self {
            origin: ray.origin.to_array(),
            inv_dir,
            near: [0, 1, 2].map(|axis| 2 * axis + negative[axis]),
            far: [0, 1, 2].map(|axis| 2 * axis + 1 - negative[axis]),
            tnear: ray.tnear,
        }
    }
}

/// Which lanes pass, one bit per lane (bit `i` for lane `i`).
pub(super) type LaneMask = u32;

/// The kernels one traversal is built on.
///
/// The box test is conservative in the way of the binary BVH's: the slab
/// distances come from the reciprocal direction and the exit distance is
/// widened by `1 + 2γ(3)` (Ize 2013), a slab whose distance is NaN (a ray
/// in a box's face plane along a zero direction component) never rejects,
/// so no box the exact ray touches is missed. The triangle pre-test
/// only names the lanes worth the exact scalar test; a lane it leaves out
/// is one the exact test would reject.
pub(super) trait Lanes {
    /// The children of `node` the ray enters within `[tnear, tfar]`, and
    /// where it enters each.
    fn enter_boxes(node: &WideNode, ray: &RayLanes, tfar: f32) -> (LaneMask, [f32; WIDTH]);

    /// The lanes of `block` that may be hit.
    fn triangle_candidates(block: &TriangleBlock, ray: &WatertightRay) -> LaneMask;
}

/// One lane at a time, with the same operations in the same order as the
/// SIMD kernel, so both give the same bits.
pub(super) struct Scalar;

/// `max(value, acc)` as the SIMD max instruction computes it: `acc` when
/// either is NaN or both are equal.
fn max_keep(value: f32, acc: f32) -> f32 {
    if value > acc { value } else { acc }
}

/// `min(value, acc)`, keeping `acc` when either is NaN or both are equal.
fn min_keep(value: f32, acc: f32) -> f32 {
    if value < acc { value } else { acc }
}

impl Lanes for Scalar {
    fn enter_boxes(node: &WideNode, ray: &RayLanes, tfar: f32) -> (LaneMask, [f32; WIDTH]) {
        let mut mask = 0;
        let mut entries = [0.0; WIDTH];
        for (lane, entry) in entries.iter_mut().enumerate() {
            let (mut enter, mut exit) = (f32::NEG_INFINITY, f32::INFINITY);
            for axis in 0..3 {
                let distance = |plane: usize| {
                    (node.planes[plane][lane] - ray.origin[axis]) * ray.inv_dir[axis]
                };
                enter = max_keep(distance(ray.near[axis]), enter);
                exit = min_keep(distance(ray.far[axis]), exit);
            }
            let enter = max_keep(enter * pullback(enter), ray.tnear);
            let exit = min_keep(exit * widening(exit), tfar);
            *entry = enter;
            mask |= LaneMask::from(enter <= exit) << lane;
        }
        (mask, entries)
    }

    fn triangle_candidates(block: &TriangleBlock, _ray: &WatertightRay) -> LaneMask {
        // Every stored triangle goes to the exact test.
        (0..WIDTH)
            .filter(|&lane| block.prim(lane).is_some())
            .fold(0, |mask, lane| mask | 1 << lane)
    }
}

/// The factor that pushes a slab exit distance away from the origin.
pub(super) fn widening(exit: f32) -> f32 {
    if exit > 0.0 { GROW } else { SHRINK }
}

/// The factor that pulls a slab entry distance towards the origin, so ties
/// on a box face resolve as in a loop over all triangles (see `ray_box`).
pub(super) fn pullback(enter: f32) -> f32 {
    if enter > 0.0 { SHRINK } else { GROW }
}

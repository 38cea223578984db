//! The [`Lanes`] kernels with x86-64 AVX2 intrinsics: all eight children's
//! slab tests in one instruction each, their ordering by the node's octant
//! order with two permutes and a compress, and all eight triangles' edge
//! functions at once.
//!
//! The box test performs the scalar kernel's operations in the same order
//! (`maxps`/`minps` keep their second operand on NaN or equality, as the
//! scalar kernel does), and orders children the same way, so both kernels
//! visit the same nodes. The triangle test evaluates the edge functions of
//! the watertight test (Woop et al. 2013) with exactly the scalar test's
//! operations (no fused multiply-add), so the values are identical, and
//! judges their signs against an error bound at least the scalar test's
//! ([`triangle_lanes`]); a lane whose three edges are beyond it with one
//! sign is finished from those values, unless its sheared distance proves
//! it behind the origin (`behind.rs`), a miss like a lane with edges
//! beyond it of both signs; every other lane takes the whole scalar test,
//! which asks the exact predicate. Each lane so gets the scalar test's
//! answer, bit for bit.

use super::behind::{AlongKz, ShearedLanes, behind_origin};
use super::candidates::filter;
use super::crossings::{BlockCrossings, block_crossings};
use super::lanes::{BoxRay, Filtered, LaneMask, Lanes, Stack, TriangleLanes, highest_lane};
use super::node::{EdgeNorms, TriangleBlock, WIDTH, WideNode};
use super::vector::{Blocks, Floats};
use crate::geometry::Ray;
use crate::geometry::triangle::{
    ABSOLUTE_ERROR, RELATIVE_ERROR, Segment, UNDERFLOW_WEIGHT, WatertightRay,
};
use std::arch::x86_64::*;

/// The AVX2 kernels; only ever inlined into traversals compiled for AVX2
/// (see `mod.rs`), on CPUs that have it.
pub(super) struct Avx2;

/// A node's box tests: which lanes hit (all bits set) and their entry
/// distances.
#[derive(Clone, Copy)]
pub(super) struct Boxes {
    hit: __m256,
    enter: __m256,
}

/// The distances where `ray` enters and leaves each child box of `node`
/// over `[ray.tnear, tfar]`, with the scalar kernel's operations in its
/// order; also the AVX-512 kernel's (`avx512.rs`).
#[inline(always)]
pub(super) fn slab_distances(node: &WideNode, ray: &BoxRay, tfar: f32) -> (__m256, __m256) {
    // SAFETY: AVX is enabled where this is inlined (see `Avx2`); the loads
    // read one 32-byte-aligned row of `node.planes` (the node is 64-byte
    // aligned, each row 32 bytes).
    unsafe {
        let mut enter = _mm256_set1_ps(ray.tnear);
        let mut exit = _mm256_set1_ps(tfar);
        for axis in 0..3 {
            let origin = _mm256_set1_ps(ray.origin[axis]);
            let [near, far] = ray.sides(axis);
            let near = _mm256_sub_ps(_mm256_load_ps(node.planes[axis][near].as_ptr()), origin);
            let far = _mm256_sub_ps(_mm256_load_ps(node.planes[axis][far].as_ptr()), origin);
            enter = _mm256_max_ps(
                _mm256_mul_ps(near, _mm256_set1_ps(ray.inv_near[axis])),
                enter,
            );
            exit = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(ray.inv_far[axis])), exit);
        }
        (enter, exit)
    }
}

/// For each 8-bit mask, the positions of its set bits in ascending order
/// (then zeros): the permutation that packs the set lanes to the front.
static COMPRESS: [[u8; WIDTH]; 1 << WIDTH] = {
    let mut table = [[0u8; WIDTH]; 1 << WIDTH];
    let mut mask = 0;
    while mask < 1 << WIDTH {
        let (mut bit, mut count) = (0, 0);
        while bit < WIDTH {
            if mask & 1 << bit != 0 {
                table[mask][count] = bit as u8;
                count += 1;
            }
            bit += 1;
        }
        mask += 1;
    }
    table
};

impl Lanes for Avx2 {
    type Boxes = Boxes;

    #[inline(always)]
    fn enter_boxes(node: &WideNode, ray: &BoxRay, tfar: f32) -> (LaneMask, Boxes) {
        let (enter, exit) = slab_distances(node, ray, tfar);
        // SAFETY: AVX is enabled where this is inlined.
        unsafe {
            let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit);
            (_mm256_movemask_ps(hit) as LaneMask, Boxes { hit, enter })
        }
    }

    #[inline(always)]
    fn push_children(
        node: &WideNode,
        _mask: LaneMask,
        boxes: &Boxes,
        octant: u32,
        stack: &mut Stack,
    ) -> u32 {
        let (children_top, entries_top) = stack.top();
        // SAFETY: AVX2 is enabled where this is inlined; `child` and `order`
        // are 32-byte rows at 32-byte-aligned offsets of the 64-byte-aligned
        // node; the compress row is 8 bytes; the two stores write the 8
        // entries `Stack::top` reserved.
        unsafe {
            // Lane j of `index`: the slot at position j of the octant's
            // order (the permutes read only the low three bits).
            let shift = _mm_cvtsi32_si128(3 * octant as i32);
            let index = _mm256_srl_epi32(_mm256_load_si256(node.order.as_ptr().cast()), shift);
            let ordered_hits =
                _mm256_movemask_ps(_mm256_permutevar8x32_ps(boxes.hit, index)) as usize;
            let children =
                _mm256_permutevar8x32_epi32(_mm256_load_si256(node.child.as_ptr().cast()), index);
            let entries = _mm256_permutevar8x32_ps(boxes.enter, index);
            let compress =
                _mm256_cvtepu8_epi32(_mm_loadl_epi64(COMPRESS[ordered_hits].as_ptr().cast()));
            _mm256_storeu_si256(
                children_top.cast(),
                _mm256_permutevar8x32_epi32(children, compress),
            );
            _mm256_storeu_ps(entries_top, _mm256_permutevar8x32_ps(entries, compress));
            // Far to near: the nearest is the last one stored; it is
            // visited now rather than pushed.
            let count = ordered_hits.count_ones() as usize;
            stack.push_all_but_last(count)
        }
    }

    #[inline(always)]
    fn push_children_in_slot_order(
        node: &WideNode,
        mask: LaneMask,
        boxes: &Boxes,
        stack: &mut Stack,
    ) -> u32 {
        let (children_top, entries_top) = stack.top();
        // SAFETY: as in `push_children`; `mask` has only the low 8 bits,
        // so its highest lane is a slot of the node.
        unsafe {
            let compress =
                _mm256_cvtepu8_epi32(_mm_loadl_epi64(COMPRESS[mask as usize].as_ptr().cast()));
            let children = _mm256_load_si256(node.child.as_ptr().cast());
            _mm256_storeu_si256(
                children_top.cast(),
                _mm256_permutevar8x32_epi32(children, compress),
            );
            _mm256_storeu_ps(entries_top, _mm256_permutevar8x32_ps(boxes.enter, compress));
            let count = mask.count_ones() as usize;
            stack.keep_all_but_last(count);
            // The child visited next, the highest slot, read from the node
            // rather than back from the stack, where it arrives through the
            // table, the permute and the store: the next node's address
            // waited on that chain (shadow rays 3-4% faster read here, the
            // monkey to dragon-48k; Xeon).
            *node.child.get_unchecked(highest_lane(mask))
        }
    }

    type TriangleRay = TriangleRay;

    #[inline(always)]
    fn triangle_ray(ray: &WatertightRay, reach: f32) -> TriangleRay {
        let axes = ray.axes();
        // An array, not a `Vec3`: indexing a `Vec3` by a run-time axis is a
        // branch per component.
        let origin = ray.origin().to_array();
        TriangleRay {
            axes,
            origin: axes.map(|k| origin[k]),
            shear: ray.shear(),
            weight_floor: RELATIVE_ERROR * reach + UNDERFLOW_WEIGHT,
            bound_factor: 2.0 * RELATIVE_ERROR * reach,
            along_kz: AlongKz {
                length: ray.direction_kz().abs(),
                sign: 0.0f32.copysign(ray.direction_kz()),
            },
        }
    }

    #[inline(always)]
    fn triangle_lanes(
        block: &TriangleBlock,
        ray: &TriangleRay,
        segment: &Segment,
    ) -> TriangleLanes {
        triangle_lanes(block, ray, segment)
    }

    #[inline(always)]
    fn block_crossings(block: &TriangleBlock, ray: &WatertightRay) -> BlockCrossings {
        block_crossings(block, ray)
    }

    #[inline(always)]
    fn filter<const PROVE_HITS: bool>(
        block: &TriangleBlock,
        norms: &EdgeNorms,
        ray: &Ray,
    ) -> Filtered {
        // SAFETY: only ever inlined into the AVX2 traversal, compiled for
        // AVX2 and FMA (see `Avx2`).
        unsafe { filter::<PROVE_HITS>(block, norms, ray) }
    }

    #[inline(always)]
    fn outlined<R>(make: impl FnOnce() -> R) -> R {
        // SAFETY: the AVX2 kernels run only on CPUs with these features.
        unsafe { outlined_for_avx2(make) }
    }
}

#[target_feature(enable = "avx2,fma,bmi1,popcnt")]
#[inline(never)]
fn outlined_for_avx2<R>(make: impl FnOnce() -> R) -> R {
    make()
}

/// A ray prepared for [`triangle_lanes`]: the watertight test's axes
/// `[kx, ky, kz]`, the origin's coordinates along them, the shear, and the
/// two per-ray terms of the error bound from the tree's reach `M`.
#[derive(Clone, Copy, Debug)]
pub(super) struct TriangleRay {
    axes: [usize; 3],
    origin: [f32; 3],
    shear: [f32; 2],
    /// `RELATIVE_ERROR·M + UNDERFLOW_WEIGHT`, added to a lane's largest
    /// sheared magnitude to give its `W`.
    weight_floor: f32,
    /// `2·RELATIVE_ERROR·M`, the factor of `W` in the bound.
    bound_factor: f32,
    along_kz: AlongKz,
}

/// [`Lanes::triangle_lanes`] for one block in 256-bit lanes ([`Avx2`],
/// and the AVX-512 kernel's lone leaves), or [`Lanes::pair_lanes`] for two
/// in 512-bit ones (`avx512.rs`), the first block's lanes lowest: the same
/// operations at either width (`vector.rs`). Written without closures (a
/// closure is a function of its own, compiled without the target
/// features, whose intrinsics would then be calls).
///
/// The edge functions are the scalar test's, operation for operation. Each
/// lane's three signs are judged against one bound, larger than each of the
/// scalar test's three (`triangle::edge_error_bound`), so as valid:
/// `(2·RELATIVE_ERROR·M)·W + ABSOLUTE_ERROR`, with `M` the tree's reach
/// from the origin ([`super::lanes::reach`], at least every corner's L1
/// distance `m` to it, by a margin that covers the rounding) and `W` the
/// lane's largest sheared magnitude `|X| + |Y|` plus `RELATIVE_ERROR·M +
/// UNDERFLOW_WEIGHT`; each scalar bound `RELATIVE_ERROR·(w_p·m_q +
/// w_q·m_p)` is at most that. A reach far above a block's own distances
/// only leaves more lanes to the scalar test: near-edge lanes are rare
/// (the exact predicate runs about once in thousands of rays), so one
/// bound per ray is cheaper than three L1 distances per corner.
#[inline(always)]
pub(super) fn triangle_lanes<B: Blocks>(
    blocks: B,
    ray: &TriangleRay,
    segment: &Segment,
) -> TriangleLanes<<B::Lanes as Floats>::Row> {
    let [kx, ky, kz] = ray.axes;
    let splat = <B::Lanes as Floats>::splat;
    let shear_x = splat(ray.shear[0]);
    let shear_y = splat(ray.shear[1]);
    let origin = [
        splat(ray.origin[0]),
        splat(ray.origin[1]),
        splat(ray.origin[2]),
    ];
    let sign_bit = splat(-0.0);
    // Each corner sheared into ray space, its sheared magnitude, and its
    // offset from the origin along kz.
    macro_rules! corner {
        ($c:expr) => {{
            let ax = blocks.row($c, kx).sub(origin[0]);
            let ay = blocks.row($c, ky).sub(origin[1]);
            let az = blocks.row($c, kz).sub(origin[2]);
            let x = ax.sub(shear_x.mul(az));
            let y = ay.sub(shear_y.mul(az));
            (x, y, x.abs().add(y.abs()), az)
        }};
    }
    let (ax, ay, ha, oa) = corner!(0);
    let (bx, by, hb, ob) = corner!(1);
    let (cx, cy, hc, oc) = corner!(2);
    let e0 = cx.mul(by).sub(cy.mul(bx));
    let e1 = ax.mul(cy).sub(ay.mul(cx));
    let e2 = bx.mul(ay).sub(by.mul(ax));
    let magnitude = ha.max(hb).max(hc);
    let w = magnitude.add(splat(ray.weight_floor));
    let bound = splat(ray.bound_factor).mul(w).add(splat(ABSOLUTE_ERROR));
    let below = bound.xor(sign_bit);
    // One sign beyond the bound on all three edges, or both signs among
    // them; a NaN edge (padding, or a result the scalar test rejects too)
    // is at worst left undecided.
    let lowest = e0.min(e1).min(e2);
    let highest = e0.max(e1).max(e2);
    let one_sign = <B::Lanes as Floats>::either(lowest.gt(bound), highest.lt(below));
    let both_signs = <B::Lanes as Floats>::both(highest.gt(bound), lowest.lt(below));
    // Triangles wholly outside the segment's window along kz, as in
    // `WatertightRay::outside` (with no NaN in a stored lane). Not along
    // kx and ky: a lane kept that those windows drop is a hit outside the
    // segment, which its distance rejects as it is finished (`Segment`),
    // and a closest-hit ray's blocks seldom hold one: testing them cost
    // the Cornell box's primary rays 1-3% and its diffuse rays 3.5-4%, the
    // other scenes' no more than their noise (Xeon, both kernels;
    // docs/performance.md).
    let lowest_offset = oa.min(ob).min(oc);
    let highest_offset = oa.max(ob).max(oc);
    let outside_kz = <B::Lanes as Floats>::either(
        highest_offset.lt(splat(segment.below[2])),
        lowest_offset.gt(splat(segment.above[2])),
    );
    let dropped = <B::Lanes as Floats>::either(blocks.padding(), outside_kz);
    let mut stored = !<B::Lanes as Floats>::bits(dropped) & <B::Lanes as Floats>::ALL;
    let mut inside = <B::Lanes as Floats>::bits(one_sign) & stored;
    // The triangle a secondary ray leaves (`behind.rs`); only for segments
    // from `t >= 0`, and only computed for lanes with corners on both
    // sides of the origin along `kz` (those wholly behind it are outside
    // the window; those wholly ahead, as a primary ray's candidates, are
    // not behind it).
    let straddling = inside
        & <B::Lanes as Floats>::bits(<B::Lanes as Floats>::both(
            lowest_offset.le(splat(0.0)),
            highest_offset.ge(splat(0.0)),
        ));
    if straddling != 0 && segment.tnear >= 0.0 {
        let lanes = ShearedLanes {
            edges: [e0, e1, e2],
            offsets: [oa, ob, oc],
            lowest_offset,
            highest_offset,
            magnitude,
        };
        let behind = behind_origin(&lanes, ray.along_kz) & straddling;
        inside &= !behind;
        stored &= !behind;
    }
    let mut lanes = TriangleLanes {
        inside,
        undecided: stored & !inside & !<B::Lanes as Floats>::bits(both_signs),
        edges: [<B::Lanes as Floats>::ZEROS; 3],
    };
    e0.store(&mut lanes.edges[0]);
    e1.store(&mut lanes.edges[1]);
    e2.store(&mut lanes.edges[2]);
    lanes
}

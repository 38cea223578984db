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
use super::lanes::{BoxRay, Filtered, LaneMask, Lanes, Stack, TriangleLanes, highest_lane};
use super::node::{BLOCK_WIDTH, EdgeNorms, TriangleBlock, WIDTH, WideNode};
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

/// [`Lanes::triangle_lanes`] for [`Avx2`], written without closures (a
/// closure is a function of its own, compiled without the AVX2 target
/// feature, whose intrinsics would then be calls).
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
pub(super) fn triangle_lanes(
    block: &TriangleBlock,
    ray: &TriangleRay,
    segment: &Segment,
) -> TriangleLanes {
    // SAFETY: only ever inlined into the AVX2 traversal (see `Avx2`); every
    // load and store covers exactly one `[f32; 8]` or `[u32; 8]` row, the
    // loaded rows 32-byte aligned (the block is).
    unsafe {
        let [kx, ky, kz] = ray.axes;
        let shear_x = _mm256_set1_ps(ray.shear[0]);
        let shear_y = _mm256_set1_ps(ray.shear[1]);
        let origin = [
            _mm256_set1_ps(ray.origin[0]),
            _mm256_set1_ps(ray.origin[1]),
            _mm256_set1_ps(ray.origin[2]),
        ];
        let sign_bit = _mm256_set1_ps(-0.0);
        // Each corner relative to the origin along kx, ky, kz, sheared into
        // ray space, and its sheared magnitude.
        macro_rules! corner {
            ($c:expr) => {{
                let rows = &block.corners[$c];
                let ax = _mm256_sub_ps(_mm256_load_ps(rows[kx].as_ptr()), origin[0]);
                let ay = _mm256_sub_ps(_mm256_load_ps(rows[ky].as_ptr()), origin[1]);
                let az = _mm256_sub_ps(_mm256_load_ps(rows[kz].as_ptr()), origin[2]);
                let x = _mm256_sub_ps(ax, _mm256_mul_ps(shear_x, az));
                let y = _mm256_sub_ps(ay, _mm256_mul_ps(shear_y, az));
                let sheared =
                    _mm256_add_ps(_mm256_andnot_ps(sign_bit, x), _mm256_andnot_ps(sign_bit, y));
                (x, y, sheared, [ax, ay, az])
            }};
        }
        macro_rules! edge {
            ($px:expr, $qy:expr, $py:expr, $qx:expr) => {
                _mm256_sub_ps(_mm256_mul_ps($px, $qy), _mm256_mul_ps($py, $qx))
            };
        }
        let (ax, ay, ha, [xa, ya, oa]) = corner!(0);
        let (bx, by, hb, [xb, yb, ob]) = corner!(1);
        let (cx, cy, hc, [xc, yc, oc]) = corner!(2);
        let e0 = edge!(cx, by, cy, bx);
        let e1 = edge!(ax, cy, ay, cx);
        let e2 = edge!(bx, ay, by, ax);
        let magnitude = _mm256_max_ps(_mm256_max_ps(ha, hb), hc);
        let w = _mm256_add_ps(magnitude, _mm256_set1_ps(ray.weight_floor));
        let bound = _mm256_add_ps(
            _mm256_mul_ps(_mm256_set1_ps(ray.bound_factor), w),
            _mm256_set1_ps(ABSOLUTE_ERROR),
        );
        let below = _mm256_xor_ps(bound, sign_bit);
        // One sign beyond the bound on all three edges, or both signs
        // among them; a NaN edge (padding, or a result the scalar test
        // rejects too) is at worst left undecided.
        let lowest = _mm256_min_ps(_mm256_min_ps(e0, e1), e2);
        let highest = _mm256_max_ps(_mm256_max_ps(e0, e1), e2);
        let one_sign = _mm256_or_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(lowest, bound),
            _mm256_cmp_ps::<_CMP_LT_OQ>(highest, below),
        );
        let both_signs = _mm256_and_ps(
            _mm256_cmp_ps::<_CMP_GT_OQ>(highest, bound),
            _mm256_cmp_ps::<_CMP_LT_OQ>(lowest, below),
        );
        let padding = _mm256_cmpeq_epi32(
            _mm256_load_si256(block.prims.as_ptr().cast()),
            _mm256_set1_epi32(TriangleBlock::PADDING as i32),
        );
        // Triangles wholly outside the segment's window along an axis
        // (`WatertightRay::outside`, with no NaN in a stored lane).
        macro_rules! outside {
            ($axis:expr, $lowest:expr, $highest:expr) => {
                _mm256_or_ps(
                    _mm256_cmp_ps::<_CMP_LT_OQ>($highest, _mm256_set1_ps(segment.below[$axis])),
                    _mm256_cmp_ps::<_CMP_GT_OQ>($lowest, _mm256_set1_ps(segment.above[$axis])),
                )
            };
        }
        let lowest_offset = _mm256_min_ps(_mm256_min_ps(oa, ob), oc);
        let highest_offset = _mm256_max_ps(_mm256_max_ps(oa, ob), oc);
        let outside = outside!(2, lowest_offset, highest_offset);
        let mut stored = !_mm256_movemask_ps(_mm256_castsi256_ps(padding)) as LaneMask
            & !_mm256_movemask_ps(outside) as LaneMask
            & 0xFF;
        let mut inside = _mm256_movemask_ps(one_sign) as LaneMask & stored;
        // The triangle a secondary ray leaves (`behind.rs`); only for
        // segments from `t >= 0`, and only computed for lanes with corners
        // on both sides of the origin along `kz` (those wholly behind it
        // are outside the window; those wholly ahead, as a primary ray's
        // candidates, are not behind it).
        let straddling = inside
            & _mm256_movemask_ps(_mm256_and_ps(
                _mm256_cmp_ps::<_CMP_LE_OQ>(lowest_offset, _mm256_setzero_ps()),
                _mm256_cmp_ps::<_CMP_GE_OQ>(highest_offset, _mm256_setzero_ps()),
            )) as LaneMask;
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
        // The windows along kx and ky only for the lanes still to be
        // finished one at a time: a secondary ray's blocks seldom have any
        // once the triangle it leaves is dropped.
        if inside != 0 {
            let across = _mm256_or_ps(
                outside!(
                    0,
                    _mm256_min_ps(_mm256_min_ps(xa, xb), xc),
                    _mm256_max_ps(_mm256_max_ps(xa, xb), xc)
                ),
                outside!(
                    1,
                    _mm256_min_ps(_mm256_min_ps(ya, yb), yc),
                    _mm256_max_ps(_mm256_max_ps(ya, yb), yc)
                ),
            );
            let across = _mm256_movemask_ps(across) as LaneMask;
            inside &= !across;
            stored &= !across;
        }
        let missed = _mm256_movemask_ps(both_signs) as LaneMask;
        let mut lanes = TriangleLanes {
            inside,
            undecided: stored & !inside & !missed,
            edges: [[0.0; BLOCK_WIDTH]; 3],
        };
        _mm256_storeu_ps(lanes.edges[0].as_mut_ptr(), e0);
        _mm256_storeu_ps(lanes.edges[1].as_mut_ptr(), e1);
        _mm256_storeu_ps(lanes.edges[2].as_mut_ptr(), e2);
        lanes
    }
}

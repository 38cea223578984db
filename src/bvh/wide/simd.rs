//! The [`Lanes`] kernels with x86-64 AVX2 intrinsics: all eight children's
//! slab tests in one instruction each, their ordering by the node's octant
//! order with two permutes and a compress, and all eight triangles' edge
//! functions at once.
//!
//! The box test performs the scalar kernel's operations in the same order
//! (`maxps`/`minps` keep their second operand on NaN or equality, as the
//! scalar kernel does), and orders children the same way, so both kernels
//! visit the same nodes. The triangle test evaluates the edge functions of
//! the watertight test (Woop et al. 2013) and their error bounds with
//! exactly the scalar test's operations (no fused multiply-add), so the
//! values are identical; a lane whose three edges are beyond their bounds
//! with one sign is finished from those values, a lane with edges beyond
//! their bounds of both signs is a miss, and every other lane takes the
//! whole scalar test, which asks the exact predicate. Each lane so gets the
//! scalar test's answer, bit for bit.

use super::lanes::{BoxRay, LaneMask, Lanes, Stack, TriangleLanes};
use super::node::{BLOCK_WIDTH, TriangleBlock, WIDTH, WideNode};
use crate::geometry::triangle::{ABSOLUTE_ERROR, RELATIVE_ERROR, UNDERFLOW_WEIGHT, WatertightRay};
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
        // SAFETY: AVX is enabled where this is inlined (see the type's
        // note); the loads read one 32-byte-aligned row of `node.planes`
        // (the node is 64-byte aligned, each row 32 bytes).
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
            let nearest = *children_top.add(count - 1);
            stack.grow(count - 1);
            nearest
        }
    }

    #[inline(always)]
    fn triangle_lanes(block: &TriangleBlock, ray: &WatertightRay) -> TriangleLanes {
        // SAFETY: only ever inlined into the AVX2 traversal (see the type).
        unsafe { triangle_lanes(block, ray) }
    }
}

/// [`Lanes::triangle_lanes`] for [`Avx2`]; the closures inside it inherit
/// its target features, so they inline.
///
/// # Safety
/// The CPU must have AVX2.
#[target_feature(enable = "avx2")]
#[inline]
unsafe fn triangle_lanes(block: &TriangleBlock, ray: &WatertightRay) -> TriangleLanes {
    // SAFETY: AVX2 is enabled; every load and store covers exactly one
    // `[f32; 8]` or `[u32; 8]` row.
    unsafe {
        let load = |row: &[f32; BLOCK_WIDTH]| _mm256_loadu_ps(row.as_ptr());
        let [kx, ky, kz] = ray.axes();
        let [shear_x, shear_y] = ray.shear();
        let (shear_x, shear_y) = (_mm256_set1_ps(shear_x), _mm256_set1_ps(shear_y));
        let o = ray.origin();
        let origin = [
            _mm256_set1_ps(o.x),
            _mm256_set1_ps(o.y),
            _mm256_set1_ps(o.z),
        ];
        let sign_bit = _mm256_set1_ps(-0.0);
        let abs = |v: __m256| _mm256_andnot_ps(sign_bit, v);
        // Each corner relative to the origin, sheared into ray space,
        // its L1 distance to the origin (`triangle::l1_length`) and its
        // weight in the error bound (`triangle::corner_weight`).
        let sheared = |corner: usize| {
            let axis = |k: usize| _mm256_sub_ps(load(&block.corners[corner][k]), origin[k]);
            let z = axis(kz);
            let length = _mm256_add_ps(_mm256_add_ps(abs(axis(0)), abs(axis(1))), abs(axis(2)));
            let x = _mm256_sub_ps(axis(kx), _mm256_mul_ps(shear_x, z));
            let y = _mm256_sub_ps(axis(ky), _mm256_mul_ps(shear_y, z));
            let weight = _mm256_add_ps(
                _mm256_add_ps(abs(x), abs(y)),
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_set1_ps(RELATIVE_ERROR), length),
                    _mm256_set1_ps(UNDERFLOW_WEIGHT),
                ),
            );
            (x, y, length, weight)
        };
        let ((ax, ay, ma, wa), (bx, by, mb, wb), (cx, cy, mc, wc)) =
            (sheared(0), sheared(1), sheared(2));
        let edge = |px: __m256, qy: __m256, py: __m256, qx: __m256| {
            _mm256_sub_ps(_mm256_mul_ps(px, qy), _mm256_mul_ps(py, qx))
        };
        // `triangle::edge_error_bound`, operation for operation.
        let bound = |wp: __m256, mp: __m256, wq: __m256, mq: __m256| {
            _mm256_add_ps(
                _mm256_mul_ps(
                    _mm256_set1_ps(RELATIVE_ERROR),
                    _mm256_add_ps(_mm256_mul_ps(wp, mq), _mm256_mul_ps(wq, mp)),
                ),
                _mm256_set1_ps(ABSOLUTE_ERROR),
            )
        };
        let edges = [
            edge(cx, by, cy, bx),
            edge(ax, cy, ay, cx),
            edge(bx, ay, by, ax),
        ];
        let bounds = [
            bound(wc, mc, wb, mb),
            bound(wa, ma, wc, mc),
            bound(wb, mb, wa, ma),
        ];
        // Beyond the bound on either side; NaN is neither.
        let positive = |i: usize| _mm256_cmp_ps::<_CMP_GT_OQ>(edges[i], bounds[i]);
        let negative =
            |i: usize| _mm256_cmp_ps::<_CMP_LT_OQ>(edges[i], _mm256_xor_ps(bounds[i], sign_bit));
        let (p0, p1, p2) = (positive(0), positive(1), positive(2));
        let (n0, n1, n2) = (negative(0), negative(1), negative(2));
        let all_one_sign = _mm256_or_ps(
            _mm256_and_ps(_mm256_and_ps(p0, p1), p2),
            _mm256_and_ps(_mm256_and_ps(n0, n1), n2),
        );
        let both_signs = _mm256_and_ps(
            _mm256_or_ps(_mm256_or_ps(p0, p1), p2),
            _mm256_or_ps(_mm256_or_ps(n0, n1), n2),
        );
        let padding = _mm256_cmpeq_epi32(
            _mm256_loadu_si256(block.prims.as_ptr().cast()),
            _mm256_set1_epi32(TriangleBlock::PADDING as i32),
        );
        let stored = !_mm256_movemask_ps(_mm256_castsi256_ps(padding)) as LaneMask & 0xFF;
        let inside = _mm256_movemask_ps(all_one_sign) as LaneMask & stored;
        let missed = _mm256_movemask_ps(both_signs) as LaneMask;
        let mut lanes = TriangleLanes {
            inside,
            undecided: stored & !inside & !missed,
            edges: [[0.0; BLOCK_WIDTH]; 3],
        };
        for (row, value) in lanes.edges.iter_mut().zip(edges) {
            _mm256_storeu_ps(row.as_mut_ptr(), value);
        }
        lanes
    }
}

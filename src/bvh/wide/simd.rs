//! The [`Lanes`] kernels with x86-64 SIMD intrinsics: all four children's
//! slab tests, and all four triangles' edge functions, in one instruction
//! each.
//!
//! The box test performs the scalar kernel's operations in the same order
//! (`maxps`/`minps` keep their second operand on NaN or equality, as the
//! scalar kernel does). The triangle pre-test evaluates the edge functions
//! of the watertight test (Woop et al. 2013) and their error bounds with
//! exactly the scalar test's operations (no fused multiply-add), so the
//! values are identical, and names a lane unless its edge functions have
//! strictly mixed signs, each beyond its error bound: those are exactly the
//! lanes the scalar test rejects without asking the exact predicate, so
//! running the scalar test on the named lanes gives the same hits, bit for
//! bit.

use super::lanes::{LaneMask, Lanes, RayLanes};
use super::node::{TriangleBlock, WIDTH, WideNode};
use crate::bvh::ray_box::{GROW, SHRINK};
use crate::geometry::triangle::{ABSOLUTE_ERROR, RELATIVE_ERROR, UNDERFLOW_WEIGHT, WatertightRay};
use std::arch::x86_64::*;

/// The SSE kernels; the traversal that uses them is compiled for AVX2 (see
/// `traverse.rs`), so they run with VEX encoding.
pub(super) struct Sse;

fn load(lanes: &[f32; WIDTH]) -> __m128 {
    // SAFETY: SSE is part of every x86-64 CPU; reads exactly the four f32
    // of `lanes`, with no alignment needed.
    unsafe { _mm_loadu_ps(lanes.as_ptr()) }
}

fn store(v: __m128) -> [f32; WIDTH] {
    let mut lanes = [0.0; WIDTH];
    // SAFETY: SSE is part of every x86-64 CPU; writes exactly the four f32
    // of `lanes`.
    unsafe { _mm_storeu_ps(lanes.as_mut_ptr(), v) };
    lanes
}

impl Lanes for Sse {
    #[inline(always)]
    fn enter_boxes(node: &WideNode, ray: &RayLanes, tfar: f32) -> (LaneMask, [f32; WIDTH]) {
        // SAFETY: SSE and SSE2 are part of every x86-64 CPU.
        unsafe {
            let mut enter = _mm_set1_ps(f32::NEG_INFINITY);
            let mut exit = _mm_set1_ps(f32::INFINITY);
            for axis in 0..3 {
                let origin = _mm_set1_ps(ray.origin[axis]);
                let inv_dir = _mm_set1_ps(ray.inv_dir[axis]);
                let distance = |plane: usize| {
                    _mm_mul_ps(_mm_sub_ps(load(&node.planes[plane]), origin), inv_dir)
                };
                enter = _mm_max_ps(distance(ray.near[axis]), enter);
                exit = _mm_min_ps(distance(ray.far[axis]), exit);
            }
            // Away from the origin for the exit, towards it for the entry
            // (the rounding bounds of `ray_box`).
            let scale = |v: __m128, positive: f32, other: f32| {
                let is_positive = _mm_cmpgt_ps(v, _mm_setzero_ps());
                let factor = _mm_or_ps(
                    _mm_and_ps(is_positive, _mm_set1_ps(positive)),
                    _mm_andnot_ps(is_positive, _mm_set1_ps(other)),
                );
                _mm_mul_ps(v, factor)
            };
            let enter = _mm_max_ps(scale(enter, SHRINK, GROW), _mm_set1_ps(ray.tnear));
            let exit = _mm_min_ps(scale(exit, GROW, SHRINK), _mm_set1_ps(tfar));
            let mask = _mm_movemask_ps(_mm_cmple_ps(enter, exit)) as LaneMask;
            (mask, store(enter))
        }
    }

    #[inline(always)]
    fn triangle_candidates(block: &TriangleBlock, ray: &WatertightRay) -> LaneMask {
        // SAFETY: SSE and SSE2 are part of every x86-64 CPU.
        unsafe {
            let [kx, ky, kz] = ray.axes();
            let [shear_x, shear_y] = ray.shear().map(|s| _mm_set1_ps(s));
            let origin = ray.origin().to_array().map(|o| _mm_set1_ps(o));
            let abs = |v: __m128| _mm_andnot_ps(_mm_set1_ps(-0.0), v);
            // Each corner relative to the origin, sheared into ray space,
            // its L1 distance to the origin (`triangle::l1_length`) and its
            // weight in the error bound (`triangle::corner_weight`).
            let sheared = |corner: usize| {
                let axis = |k: usize| _mm_sub_ps(load(&block.corners[corner][k]), origin[k]);
                let z = axis(kz);
                let length = _mm_add_ps(_mm_add_ps(abs(axis(0)), abs(axis(1))), abs(axis(2)));
                let x = _mm_sub_ps(axis(kx), _mm_mul_ps(shear_x, z));
                let y = _mm_sub_ps(axis(ky), _mm_mul_ps(shear_y, z));
                let weight = _mm_add_ps(
                    _mm_add_ps(abs(x), abs(y)),
                    _mm_add_ps(
                        _mm_mul_ps(_mm_set1_ps(RELATIVE_ERROR), length),
                        _mm_set1_ps(UNDERFLOW_WEIGHT),
                    ),
                );
                (x, y, length, weight)
            };
            let ((ax, ay, ma, wa), (bx, by, mb, wb), (cx, cy, mc, wc)) =
                (sheared(0), sheared(1), sheared(2));
            let edge = |px: __m128, qy: __m128, py: __m128, qx: __m128| {
                _mm_sub_ps(_mm_mul_ps(px, qy), _mm_mul_ps(py, qx))
            };
            // `triangle::edge_error_bound`, operation for operation.
            let bound = |wp: __m128, mp: __m128, wq: __m128, mq: __m128| {
                _mm_add_ps(
                    _mm_mul_ps(
                        _mm_set1_ps(RELATIVE_ERROR),
                        _mm_add_ps(_mm_mul_ps(wp, mq), _mm_mul_ps(wq, mp)),
                    ),
                    _mm_set1_ps(ABSOLUTE_ERROR),
                )
            };
            let edges = [
                (edge(cx, by, cy, bx), bound(wc, mc, wb, mb)),
                (edge(ax, cy, ay, cx), bound(wa, ma, wc, mc)),
                (edge(bx, ay, by, ax), bound(wb, mb, wa, ma)),
            ];
            let zero = _mm_setzero_ps();
            let any = |compare: &dyn Fn(__m128, __m128) -> __m128| {
                edges
                    .iter()
                    .fold(zero, |acc, &(e, b)| _mm_or_ps(acc, compare(e, b)))
            };
            let negative = any(&|e, _| _mm_cmplt_ps(e, zero));
            let positive = any(&|e, _| _mm_cmpgt_ps(e, zero));
            let uncertain = any(&|e, b| _mm_cmple_ps(abs(e), b));
            let mixed = _mm_movemask_ps(_mm_and_ps(negative, positive)) as LaneMask;
            let recomputed = _mm_movemask_ps(uncertain) as LaneMask;
            let stored = (0..WIDTH)
                .filter(|&lane| block.prim(lane).is_some())
                .fold(0, |mask, lane| mask | 1 << lane);
            (!mixed | recomputed) & stored
        }
    }
}

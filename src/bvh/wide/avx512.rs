//! The [`Lanes`] kernels with x86-64 AVX-512 (F, VL, DQ) on 256-bit
//! registers, as Embree runs its AVX-512 kernels on CPUs of this kind
//! (`frequency_level = simd256`): the AVX2 kernel's box and triangle tests
//! (`simd.rs`) with their lane masks in mask registers, and the children a
//! ray enters ordered by the node's octant order and packed onto the stack
//! with `vcompress` instead of a table of permutations; all compiled with
//! the 32 vector registers AVX-512 brings. With `PAIRS`
//! ([`super::Kernel::Avx512Zmm`]) one thing runs in 512-bit registers:
//! when a closest-hit ray's next leaf to pop is one it enters before its
//! best hit, the two leaves' blocks take the triangle test in one pass of
//! 16 lanes ([`Lanes::pair_lanes`]).
//!
//! The distances and edge functions are the AVX2 kernel's, so it enters the
//! same boxes, orders children the same way and finishes the same triangle
//! lanes as the scalar kernel (a paired leaf's a step early, which changes
//! no answer: the best hit is the lowest over every triangle hit).

use super::crossings::{BlockCrossings, block_crossings};
use super::lanes::{BoxRay, Filtered, LaneMask, Lanes, Stack, TriangleLanes, highest_lane};
use super::node::{BLOCK_WIDTH, EdgeNorms, TriangleBlock, WideNode};
use super::simd::{Avx2, TriangleRay, slab_distances, triangle_lanes};
use crate::geometry::Ray;
use crate::geometry::triangle::{Segment, WatertightRay};
use std::arch::x86_64::*;

/// The AVX-512 kernels, pairing closest-hit leaves in 512-bit registers
/// with `PAIRS`; only ever inlined into traversals compiled for AVX-512 F,
/// VL and DQ (see `mod.rs`), on CPUs that have them.
pub(super) struct Avx512<const PAIRS: bool>;

/// A node's box tests: the entry and exit distances of all eight children.
#[derive(Clone, Copy)]
pub(super) struct Boxes {
    enter: __m256,
    exit: __m256,
}

impl<const PAIRS: bool> Lanes for Avx512<PAIRS> {
    type Boxes = Boxes;

    #[inline(always)]
    fn enter_boxes(node: &WideNode, ray: &BoxRay, tfar: f32) -> (LaneMask, Boxes) {
        let (enter, exit) = slab_distances(node, ray, tfar);
        // SAFETY: AVX-512 F and VL are enabled where this is inlined.
        let hit = unsafe { _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit) };
        (LaneMask::from(hit), Boxes { enter, exit })
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
        // SAFETY: AVX-512 F and VL are enabled where this is inlined;
        // `child` and `order` are 32-byte rows at 32-byte-aligned offsets of
        // the 64-byte-aligned node; the two stores write the 8 entries
        // `Stack::top` reserved.
        unsafe {
            // Lane j of `index`: the slot at position j of the octant's
            // order (the permutes read only the low three bits).
            let shift = _mm_cvtsi32_si128(3 * octant as i32);
            let index = _mm256_srl_epi32(_mm256_load_si256(node.order.as_ptr().cast()), shift);
            let enter = _mm256_permutexvar_ps(index, boxes.enter);
            let exit = _mm256_permutexvar_ps(index, boxes.exit);
            let ordered_hits = _mm256_cmp_ps_mask::<_CMP_LE_OQ>(enter, exit);
            let children =
                _mm256_permutexvar_epi32(index, _mm256_load_si256(node.child.as_ptr().cast()));
            _mm256_storeu_si256(
                children_top.cast(),
                _mm256_maskz_compress_epi32(ordered_hits, children),
            );
            _mm256_storeu_ps(entries_top, _mm256_maskz_compress_ps(ordered_hits, enter));
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
            let hits = mask as __mmask8;
            let children = _mm256_load_si256(node.child.as_ptr().cast());
            _mm256_storeu_si256(
                children_top.cast(),
                _mm256_maskz_compress_epi32(hits, children),
            );
            _mm256_storeu_ps(entries_top, _mm256_maskz_compress_ps(hits, boxes.enter));
            let count = mask.count_ones() as usize;
            stack.keep_all_but_last(count);
            // Read from the node, as in `Avx2`'s (here 1% faster).
            *node.child.get_unchecked(highest_lane(mask))
        }
    }

    type TriangleRay = TriangleRay;

    #[inline(always)]
    fn triangle_ray(ray: &WatertightRay, reach: f32) -> TriangleRay {
        Avx2::triangle_ray(ray, reach)
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

    /// Two blocks in the 512-bit registers, at about the cost of one in
    /// 256-bit ones on an AMD EPYC (the Cornell box's primary and diffuse
    /// rays 5-6% faster, the monkey's and the dragons' within 1%), but
    /// not on an Intel Xeon ([`super::Kernel::prefers_zmm`]).
    const PAIRS: bool = PAIRS;

    #[inline(always)]
    fn pair_lanes(
        first: &TriangleBlock,
        second: &TriangleBlock,
        ray: &TriangleRay,
        segment: &Segment,
    ) -> TriangleLanes<[f32; 2 * BLOCK_WIDTH]> {
        triangle_lanes([first, second], ray, segment)
    }

    #[inline(always)]
    fn filter<const PROVE_HITS: bool>(
        block: &TriangleBlock,
        norms: &EdgeNorms,
        ray: &Ray,
    ) -> Filtered {
        Avx2::filter::<PROVE_HITS>(block, norms, ray)
    }

    #[inline(always)]
    fn outlined<R>(make: impl FnOnce() -> R) -> R {
        // SAFETY: the AVX-512 kernels run only on CPUs with these features.
        unsafe { outlined_for_avx512(make) }
    }
}

#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx2,fma,bmi1,popcnt")]
#[inline(never)]
fn outlined_for_avx512<R>(make: impl FnOnce() -> R) -> R {
    make()
}

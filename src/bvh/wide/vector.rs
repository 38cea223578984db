//! The f32 lanes the triangle kernel works on, at two widths behind one
//! interface: one block of eight triangles in AVX2's 256-bit registers,
//! or two blocks in AVX-512's 512-bit ones. The triangle kernel
//! (`simd::triangle_lanes`) and the behind-the-origin test (`behind.rs`)
//! are written once against it, so both widths perform the same
//! operations in the same order and give the same bits.
//!
//! Every method is only ever inlined into code compiled for the width's
//! instruction set (the traversals in `mod.rs`), on CPUs that have it.

use super::lanes::LaneMask;
use super::node::{BLOCK_WIDTH, TriangleBlock};
use std::arch::x86_64::*;

/// Lanes of f32, with the comparisons' results as [`Floats::Mask`].
pub(super) trait Floats: Copy {
    /// Which lanes a comparison holds for.
    type Mask: Copy;
    /// Where the lanes are stored, one f32 each.
    type Row: AsRef<[f32]>;
    /// Every lane's bit.
    const ALL: LaneMask;
    /// A row of zeros, for [`Floats::store`] to fill.
    const ZEROS: Self::Row;

    fn splat(value: f32) -> Self;
    fn add(self, other: Self) -> Self;
    fn sub(self, other: Self) -> Self;
    fn mul(self, other: Self) -> Self;
    /// `other` where either is NaN or both are equal, as `minps`.
    fn min(self, other: Self) -> Self;
    /// `other` where either is NaN or both are equal, as `maxps`.
    fn max(self, other: Self) -> Self;
    fn xor(self, other: Self) -> Self;
    fn and(self, other: Self) -> Self;
    /// Each lane with its sign bit cleared.
    fn abs(self) -> Self;
    /// Ordered comparisons: false wherever a lane is NaN.
    fn gt(self, other: Self) -> Self::Mask;
    fn lt(self, other: Self) -> Self::Mask;
    fn le(self, other: Self) -> Self::Mask;
    fn ge(self, other: Self) -> Self::Mask;
    fn either(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    fn both(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// One bit per lane, lane `i` in bit `i`.
    fn bits(mask: Self::Mask) -> LaneMask;
    fn store(self, row: &mut Self::Row);
}

/// The blocks one pass of the triangle kernel tests, read row by row: one
/// block in 256-bit lanes, or two in 512-bit ones, the first one's lanes
/// lowest.
pub(super) trait Blocks: Copy {
    type Lanes: Floats;

    /// `corners[corner][axis]` of every block.
    fn row(self, corner: usize, axis: usize) -> Self::Lanes;

    /// The lanes holding no triangle.
    fn padding(self) -> <Self::Lanes as Floats>::Mask;
}

impl Blocks for &TriangleBlock {
    type Lanes = __m256;

    #[inline(always)]
    fn row(self, corner: usize, axis: usize) -> __m256 {
        // SAFETY: AVX is enabled where this is inlined; the row is 32
        // bytes at a 32-byte-aligned offset of the 64-byte-aligned block.
        unsafe { _mm256_load_ps(self.corners[corner][axis].as_ptr()) }
    }

    #[inline(always)]
    fn padding(self) -> __m256 {
        // SAFETY: as in `row`, for the row of prim ids.
        unsafe {
            _mm256_castsi256_ps(_mm256_cmpeq_epi32(
                _mm256_load_si256(self.prims.as_ptr().cast()),
                _mm256_set1_epi32(TriangleBlock::PADDING as i32),
            ))
        }
    }
}

impl Blocks for [&TriangleBlock; 2] {
    type Lanes = __m512;

    #[inline(always)]
    fn row(self, corner: usize, axis: usize) -> __m512 {
        let [first, second] = self;
        // SAFETY: AVX-512 F and DQ are enabled where this is inlined; each
        // load is one block's 32-byte-aligned row.
        unsafe {
            _mm512_insertf32x8::<1>(
                _mm512_castps256_ps512(_mm256_load_ps(first.corners[corner][axis].as_ptr())),
                _mm256_load_ps(second.corners[corner][axis].as_ptr()),
            )
        }
    }

    #[inline(always)]
    fn padding(self) -> __mmask16 {
        let [first, second] = self;
        // SAFETY: as in `row`, for the rows of prim ids.
        unsafe {
            let prims = _mm512_inserti64x4::<1>(
                _mm512_castsi256_si512(_mm256_load_si256(first.prims.as_ptr().cast())),
                _mm256_load_si256(second.prims.as_ptr().cast()),
            );
            _mm512_cmpeq_epi32_mask(prims, _mm512_set1_epi32(TriangleBlock::PADDING as i32))
        }
    }
}

/// The methods of [`Floats`] that are one intrinsic each, from one
/// width's intrinsics: `$compare` returns that width's mask.
macro_rules! one_intrinsic_each {
    (
        $set1:ident, $add:ident, $sub:ident, $mul:ident, $min:ident, $max:ident,
        $xor:ident, $and:ident, $compare:ident
    ) => {
        // SAFETY (every method): the width's instruction set is enabled
        // where these are inlined (the module).
        #[inline(always)]
        fn splat(value: f32) -> Self {
            unsafe { $set1(value) }
        }
        one_intrinsic_each!(@binary add $add, sub $sub, mul $mul, min $min, max $max, xor $xor, and $and);
        one_intrinsic_each!(@compare $compare, gt _CMP_GT_OQ, lt _CMP_LT_OQ, le _CMP_LE_OQ, ge _CMP_GE_OQ);
    };
    (@binary $($method:ident $intrinsic:ident),*) => {
        $(
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                unsafe { $intrinsic(self, other) }
            }
        )*
    };
    (@compare $compare:ident, $($method:ident $predicate:ident),*) => {
        $(
            #[inline(always)]
            fn $method(self, other: Self) -> Self::Mask {
                unsafe { $compare::<$predicate>(self, other) }
            }
        )*
    };
}

impl Floats for __m256 {
    type Mask = __m256;
    type Row = [f32; BLOCK_WIDTH];
    const ALL: LaneMask = (1 << BLOCK_WIDTH) - 1;
    const ZEROS: Self::Row = [0.0; BLOCK_WIDTH];

    one_intrinsic_each!(
        _mm256_set1_ps,
        _mm256_add_ps,
        _mm256_sub_ps,
        _mm256_mul_ps,
        _mm256_min_ps,
        _mm256_max_ps,
        _mm256_xor_ps,
        _mm256_and_ps,
        _mm256_cmp_ps
    );

    // SAFETY (every method below): AVX is enabled where these are inlined.
    #[inline(always)]
    fn abs(self) -> Self {
        unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self) }
    }
    #[inline(always)]
    fn either(a: Self, b: Self) -> Self {
        unsafe { _mm256_or_ps(a, b) }
    }
    #[inline(always)]
    fn both(a: Self, b: Self) -> Self {
        unsafe { _mm256_and_ps(a, b) }
    }
    #[inline(always)]
    fn bits(mask: Self) -> LaneMask {
        unsafe { _mm256_movemask_ps(mask) as LaneMask }
    }
    #[inline(always)]
    fn store(self, row: &mut [f32; BLOCK_WIDTH]) {
        unsafe { _mm256_storeu_ps(row.as_mut_ptr(), self) }
    }
}

impl Floats for __m512 {
    type Mask = __mmask16;
    type Row = [f32; 2 * BLOCK_WIDTH];
    const ALL: LaneMask = (1 << (2 * BLOCK_WIDTH)) - 1;
    const ZEROS: Self::Row = [0.0; 2 * BLOCK_WIDTH];

    one_intrinsic_each!(
        _mm512_set1_ps,
        _mm512_add_ps,
        _mm512_sub_ps,
        _mm512_mul_ps,
        _mm512_min_ps,
        _mm512_max_ps,
        _mm512_xor_ps,
        _mm512_and_ps,
        _mm512_cmp_ps_mask
    );

    // SAFETY (every method below): AVX-512 F is enabled where these are
    // inlined.
    #[inline(always)]
    fn abs(self) -> Self {
        unsafe { _mm512_abs_ps(self) }
    }
    #[inline(always)]
    fn either(a: __mmask16, b: __mmask16) -> __mmask16 {
        a | b
    }
    #[inline(always)]
    fn both(a: __mmask16, b: __mmask16) -> __mmask16 {
        a & b
    }
    #[inline(always)]
    fn bits(mask: __mmask16) -> LaneMask {
        LaneMask::from(mask)
    }
    #[inline(always)]
    fn store(self, row: &mut [f32; 2 * BLOCK_WIDTH]) {
        unsafe { _mm512_storeu_ps(row.as_mut_ptr(), self) }
    }
}

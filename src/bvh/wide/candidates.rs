//! The any-hit traversal's filter on a block (also incoherent closest-hit
//! rays' where the leaves are sparse, `leaf_fill.rs`): all eight lanes through
//! Möller and Trumbore's test ("Fast, Minimum Storage Ray/Triangle
//! Intersection", JGT 2(1), 1997, arranged as in Embree's
//! `MoellerTrumboreIntersector1`), in f32 with fused multiply-adds,
//! dropping only the lanes it proves the watertight test misses. The rest,
//! a ray's hits and a few near misses, take the whole scalar test
//! ([`crate::geometry::triangle::WatertightRay::intersect_in`]), so the
//! answer is the scalar test's; the filter needs neither the shear nor the
//! behind-the-origin test, so a ray none of whose lanes survive never
//! makes the watertight test's per-ray set-up.
//!
//! With `C = p0 - o`, `e1 = p0 - p1`, `e2 = p2 - p0`, `N = e2 × e1` and
//! `R = C × D`, the line `o + tD` meets the closed triangle when
//! `den = N·D ≠ 0` and, with `s` the sign of `den`, `U = s·R·e2 >= 0`,
//! `V = s·R·e1 >= 0` and `U + V <= |den|`, at `t = s·N·C / |den|`. The
//! watertight test hits only such lanes: its edge signs are the exact ones
//! wherever it decides them, and they are the signs of these barycentric
//! numerators; its distance is the f64 quotient of `(p0 - o)·N` and `D·N`,
//! the same `T` and `den`, rounded to f32 and kept when in `[tnear, tfar]`.
//!
//! Each of `den`, `U`, `V`, `T` is a triple product of `C`, `D`, `e1`,
//! `e2`, each input rounded once, evaluated with at most eight roundings a
//! monomial: within `γ8·P` of its exact value, `P` the sum of its six
//! monomials' magnitudes, at most the product of the three vectors' L1
//! norms (`a` for `C`, `b1`, `b2` for the edges, `dd` for `D`; the edges'
//! `b1 + b2` and `b1·b2` are made with the tree, rounded up, in
//! [`EdgeNorms`]). The filter takes twice that with `16ε = 32u` for `γ8`,
//! from norms each padded by `2^-32`: the factor of two covers the
//! rounding of `a` (made here from the rounded `C`, it may fall a few `u`
//! short of the exact one's) and of the comparisons' right-hand sides,
//! and the padding every result flushed to zero (FTZ) or input read as
//! zero (DAZ), each below `2^-126` and at most `u·2^-96` times the norms
//! it multiplies. The scalar test's f64 values of the same monomials err
//! by under `2^-50·P`. A lane is dropped only when
//! `|den|` exceeds its bound, so the sign is known, and then when
//! `min(U, V)` is below `-bound`, `U + V` above `|den|` by more than the
//! bounds, or `T` below `|den|·tnear` or above `|den|·tfar` by more than
//! `T`'s bound and the ends' share of `den`'s, with each end first moved
//! outwards by `2^-20` of itself and `2^-100`: then the exact `t` lies
//! beyond the end by more than the f64 evaluation and the rounding to f32
//! can cover, so the scalar test's distance falls outside too (never a
//! `-0.0` from a tiny negative `t`, which `2^-100` keeps away from zero).
//!
//! Asked to, the filter also proves hits, the same bounds read the other
//! way, so that an any-hit ray need not take the scalar test to learn that
//! a lane is hit (most lanes left are hits: 0.17 of the 0.19 a shadow ray
//! on the monkey). A lane is proved hit when `|den|` exceeds twice its
//! bound and the margin below, `min(U, V)` exceeds its bound, `U + V` is
//! below `|den|` by more than the bounds, and `T` is above `|den|·tnear`
//! and below `|den|·tfar` by more than the bounds, each end moved inwards
//! by `2^-20` of itself and `2^-100` (after clamping it to `±2^100`).
//! Then the exact `U`, `V` and `|den| - U - V` are positive, so the three
//! exact edge signs the watertight test decides agree; the exact `t` lies
//! inside the segment by more than the f64 evaluation and the rounding to
//! f32 move it, so its distance is kept, finite, and (at `tnear >= 0`) not
//! behind the origin; and the exact hit point lies inside the segment's
//! window along every axis, so [`Segment`](crate::geometry::triangle::Segment)
//! keeps the triangle. Its other two checks need the margin on `|den|`:
//! - the geometric normal made in f32 is not zero: a component of the
//!   exact `N` is at least `|N·D| / dd > 1.5·den's bound / dd = 48u·b1·b2`,
//!   beyond the `u·b1·b2` its two products' rounding can take off;
//! - the f32 determinant of the sheared edge functions is not zero: their
//!   exact values share a sign and sum to `|den| / |D_kz|`, so the largest
//!   is at least `|den| / 3dd`, while each errs by at most
//!   `32.1u·(b1 + b2)·M + 273u²·M² + 2^-121·M + 2^-122`, `M <= a + b1 + b2`
//!   the farthest corner's L1 distance to the origin: a corner's sheared
//!   coordinates are those of its offset from the hit point, whose L1 norm
//!   is at most `b1 + b2` (the bound in `geometry::triangle` with that
//!   magnitude). The margin, `dd` times `2^-17·(b1 + b2)·M + 2^-37·M² +
//!   2^-100·M + 2^-100` with `M` taken as `a + b1 + b2`, is more than three
//!   times that, so the largest edge function keeps its sign and value.
//!
//! A proof also needs `a + b1 + b2` and `dd` below `2^40`, so that no f32
//! value on either side overflows. Only blocks with a lane left make it.

use super::lanes::{Filtered, LaneMask};
use super::node::{EdgeNorms, NORM_PAD, TriangleBlock};
use crate::geometry::Ray;
use std::arch::x86_64::*;

/// Twice `γ8` with room: `16ε = 32u`.
const ERROR: f32 = 16.0 * f32::EPSILON;

/// Added to every L1 norm; see the module.
const PAD: f32 = NORM_PAD;

/// How far each end of the segment is moved outwards, relative to itself
/// and absolutely.
const END_RELATIVE: f32 = 1.0 / (1 << 20) as f32;
const END_ABSOLUTE: f32 = 1.0 / (1u128 << 100) as f32;

/// The lanes of `block` that `ray`'s watertight test may hit within
/// `[tnear, tfar]` (every other stored lane it misses), and with
/// `PROVE_HITS`, among them, lanes it hits (see the module). `norms` are
/// the block's edge norms, made with it ([`EdgeNorms`]).
///
/// # Safety
/// Only inlined into code compiled for AVX2 and FMA, on CPUs that have
/// them.
#[inline(always)]
pub(super) unsafe fn filter<const PROVE_HITS: bool>(
    block: &TriangleBlock,
    norms: &EdgeNorms,
    ray: &Ray,
) -> Filtered {
    // SAFETY: as this function's.
    let may_hit = unsafe { may_hit(block, &terms(block, norms, ray), ray) };
    // Most blocks leave no lane: the proof is made only for the rest.
    let hit = if PROVE_HITS && may_hit != 0 {
        // SAFETY: this CPU has AVX2 and FMA (this function's contract).
        unsafe { proved_hits(block, norms, ray) & may_hit }
    } else {
        0
    };
    Filtered { may_hit, hit }
}

/// The filter's values for the eight lanes of a block: `|den|`, and `U`,
/// `V`, `T` signed by `den`'s sign; their bounds; the norms `a` and
/// `b1 + b2`, and `dd` (see the module).
#[derive(Clone, Copy)]
struct Terms {
    abs_den: __m256,
    u: __m256,
    v: __m256,
    t: __m256,
    uv_bound: __m256,
    den_bound: __m256,
    t_bound: __m256,
    a: __m256,
    b_sum: __m256,
    direction_norm: f32,
}

impl Terms {
    /// How far `U + V` may be from `|den|` with the sign of `|den| - U - V`
    /// still unknown: `2·bound(U, V) + bound(den)`.
    ///
    /// # Safety
    /// As [`filter`].
    #[inline(always)]
    unsafe fn uv_margin(&self) -> __m256 {
        // SAFETY: AVX is enabled where this is inlined.
        unsafe { _mm256_add_ps(_mm256_add_ps(self.uv_bound, self.uv_bound), self.den_bound) }
    }

    /// How far `T` may be from `|den|·end` with the side of `end` that the
    /// distance lies on still unknown: `bound(T) + bound(den)·|end|`.
    ///
    /// # Safety
    /// As [`filter`].
    #[inline(always)]
    unsafe fn t_margin(&self, end: f32) -> __m256 {
        // SAFETY: AVX and FMA are enabled where this is inlined.
        unsafe { _mm256_fmadd_ps(self.den_bound, _mm256_set1_ps(end.abs()), self.t_bound) }
    }
}

/// The [`Terms`] of `block` for `ray`.
///
/// # Safety
/// As [`filter`].
#[inline(always)]
unsafe fn terms(block: &TriangleBlock, norms: &EdgeNorms, ray: &Ray) -> Terms {
    // SAFETY: AVX2 and FMA are enabled where this is inlined; every load
    // reads one 32-byte-aligned row of the block or of its norms.
    unsafe {
        let splat = _mm256_set1_ps;
        let sign_bit = splat(-0.0);
        macro_rules! row {
            ($corner:expr, $axis:expr) => {
                _mm256_load_ps(block.corners[$corner][$axis].as_ptr())
            };
        }
        macro_rules! cross {
            ($a:expr, $b:expr) => {{
                let (a, b) = ($a, $b);
                [
                    _mm256_fmsub_ps(a[1], b[2], _mm256_mul_ps(a[2], b[1])),
                    _mm256_fmsub_ps(a[2], b[0], _mm256_mul_ps(a[0], b[2])),
                    _mm256_fmsub_ps(a[0], b[1], _mm256_mul_ps(a[1], b[0])),
                ]
            }};
        }
        macro_rules! dot {
            ($a:expr, $b:expr) => {{
                let (a, b) = ($a, $b);
                _mm256_fmadd_ps(
                    a[2],
                    b[2],
                    _mm256_fmadd_ps(a[1], b[1], _mm256_mul_ps(a[0], b[0])),
                )
            }};
        }
        macro_rules! padded_norm {
            ($v:expr) => {{
                let v = $v;
                _mm256_add_ps(
                    _mm256_add_ps(
                        _mm256_andnot_ps(sign_bit, v[0]),
                        _mm256_andnot_ps(sign_bit, v[1]),
                    ),
                    _mm256_add_ps(_mm256_andnot_ps(sign_bit, v[2]), splat(PAD)),
                )
            }};
        }
        // Macros, not closures: a closure is a function of its own,
        // compiled without the target features, whose intrinsics would be
        // calls.
        macro_rules! per_axis {
            (|$axis:ident| $value:expr) => {
                [
                    {
                        let $axis = 0;
                        $value
                    },
                    {
                        let $axis = 1;
                        $value
                    },
                    {
                        let $axis = 2;
                        $value
                    },
                ]
            };
        }
        let direction = per_axis!(|axis| splat(ray.dir[axis]));
        let direction_norm = ray.dir.abs().element_sum() + PAD;
        let p0 = per_axis!(|axis| row!(0, axis));
        let e1 = per_axis!(|axis| _mm256_sub_ps(p0[axis], row!(1, axis)));
        let e2 = per_axis!(|axis| _mm256_sub_ps(row!(2, axis), p0[axis]));
        let c = per_axis!(|axis| _mm256_sub_ps(p0[axis], splat(ray.origin[axis])));
        let a = padded_norm!(c);
        let b_sum = _mm256_load_ps(norms.sum.as_ptr());
        let edges = _mm256_load_ps(norms.product.as_ptr());

        let n = cross!(e2, e1);
        let r = cross!(c, direction);
        let den = dot!(n, direction);
        let sign = _mm256_and_ps(den, sign_bit);
        Terms {
            abs_den: _mm256_andnot_ps(sign_bit, den),
            u: _mm256_xor_ps(dot!(r, e2), sign),
            v: _mm256_xor_ps(dot!(r, e1), sign),
            t: _mm256_xor_ps(dot!(n, c), sign),
            uv_bound: _mm256_mul_ps(_mm256_mul_ps(a, b_sum), splat(ERROR * direction_norm)),
            den_bound: _mm256_mul_ps(edges, splat(ERROR * direction_norm)),
            t_bound: _mm256_mul_ps(_mm256_mul_ps(edges, a), splat(ERROR)),
            a,
            b_sum,
            direction_norm,
        }
    }
}

/// The stored lanes of `block` the filter does not prove missed.
///
/// # Safety
/// As [`filter`].
#[inline(always)]
unsafe fn may_hit(block: &TriangleBlock, terms: &Terms, ray: &Ray) -> LaneMask {
    let Terms {
        abs_den,
        u,
        v,
        t,
        uv_bound,
        den_bound,
        ..
    } = *terms;
    // SAFETY: AVX2 and FMA are enabled where this is inlined; the load
    // reads the block's 32-byte-aligned row of prim ids.
    unsafe {
        let splat = _mm256_set1_ps;
        let signed = _mm256_cmp_ps::<_CMP_GT_OQ>(abs_den, den_bound);
        let mut outside =
            _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_min_ps(u, v), _mm256_xor_ps(uv_bound, splat(-0.0)));
        let uv_limit = _mm256_add_ps(abs_den, terms.uv_margin());
        outside = _mm256_or_ps(
            outside,
            _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_add_ps(u, v), uv_limit),
        );
        let (tnear, tfar) = (ray.tnear, ray.tfar);
        let before = _mm256_fmsub_ps(abs_den, splat(widened(tnear, -1.0)), terms.t_margin(tnear));
        let beyond = _mm256_fmadd_ps(abs_den, splat(widened(tfar, 1.0)), terms.t_margin(tfar));
        outside = _mm256_or_ps(outside, _mm256_cmp_ps::<_CMP_LT_OQ>(t, before));
        outside = _mm256_or_ps(outside, _mm256_cmp_ps::<_CMP_GT_OQ>(t, beyond));

        let padding = _mm256_cmpeq_epi32(
            _mm256_load_si256(block.prims.as_ptr().cast()),
            _mm256_set1_epi32(TriangleBlock::PADDING as i32),
        );
        let dropped = _mm256_or_ps(_mm256_and_ps(outside, signed), _mm256_castsi256_ps(padding));
        !(_mm256_movemask_ps(dropped) as LaneMask) & 0xFF
    }
}

/// The lanes of `block` the filter proves `ray`'s watertight test hits
/// (see the module), padding included: the caller keeps those it may hit.
/// Out of line, its terms made again: kept alive for it, they crowded the
/// registers of the traversal's common path, where no lane is left. Cold,
/// so that the traversal keeps the ray's constants in registers and saves
/// them only around this call, not on the stack for every ray and back
/// after every leaf: a Cornell box shadow ray ran 481 instructions instead
/// of 506 (AVX2 kernel, callgrind), its misses one at a time 4% faster
/// (Xeon, AVX-512).
///
/// # Safety
/// The CPU has AVX2 and FMA.
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
#[cold]
unsafe fn proved_hits(block: &TriangleBlock, norms: &EdgeNorms, ray: &Ray) -> LaneMask {
    // SAFETY: this function is compiled for AVX2 and FMA.
    let terms = unsafe { terms(block, norms, ray) };
    let Terms {
        abs_den,
        u,
        v,
        t,
        uv_bound,
        den_bound,
        a,
        b_sum,
        direction_norm,
        ..
    } = terms;
    if direction_norm >= LARGEST {
        return 0;
    }
    let splat = _mm256_set1_ps;
    let reach = _mm256_add_ps(a, b_sum);
    let slack = _mm256_fmadd_ps(
        reach,
        _mm256_fmadd_ps(
            b_sum,
            splat(SHEARED_RELATIVE),
            _mm256_fmadd_ps(reach, splat(SHEARED_SQUARED), splat(TINY)),
        ),
        splat(TINY),
    );
    let den_floor = _mm256_fmadd_ps(
        slack,
        splat(direction_norm),
        _mm256_add_ps(den_bound, den_bound),
    );
    let mut inside = _mm256_and_ps(
        _mm256_cmp_ps::<_CMP_GT_OQ>(abs_den, den_floor),
        _mm256_cmp_ps::<_CMP_LT_OQ>(reach, splat(LARGEST)),
    );
    inside = _mm256_and_ps(
        inside,
        _mm256_cmp_ps::<_CMP_GT_OQ>(_mm256_min_ps(u, v), uv_bound),
    );
    // SAFETY: as above.
    let uv_ceiling = _mm256_sub_ps(abs_den, unsafe { terms.uv_margin() });
    inside = _mm256_and_ps(
        inside,
        _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_add_ps(u, v), uv_ceiling),
    );
    let tnear = ray.tnear.max(-LARGEST_DISTANCE);
    let tfar = ray.tfar.min(LARGEST_DISTANCE);
    // SAFETY: as above.
    let (near_margin, far_margin) = unsafe { (terms.t_margin(tnear), terms.t_margin(tfar)) };
    let after = _mm256_fmadd_ps(abs_den, splat(widened(tnear, 1.0)), near_margin);
    let until = _mm256_fmsub_ps(abs_den, splat(widened(tfar, -1.0)), far_margin);
    inside = _mm256_and_ps(inside, _mm256_cmp_ps::<_CMP_GT_OQ>(t, after));
    inside = _mm256_and_ps(inside, _mm256_cmp_ps::<_CMP_LT_OQ>(t, until));
    _mm256_movemask_ps(inside) as LaneMask
}

/// A proof of a hit needs every corner's L1 distance to the origin, and
/// the direction's L1 norm, below this: then no f32 value of the filter or
/// of the watertight test overflows.
const LARGEST: f32 = (1u64 << 40) as f32;

/// A proved hit's distance lies within `±2^100`, so that it is finite in
/// f32 whatever the interval.
const LARGEST_DISTANCE: f32 = (1u128 << 100) as f32;

/// The terms by which `|den|` must exceed twice its bound, per unit of the
/// direction's L1 norm, for the watertight test's sheared edge functions
/// to keep a nonzero determinant (see the module): `2^-17 = 128u` times
/// the edges' norms and the corners' reach, `2^-37 = 2048u²` times the
/// reach squared, and `2^-100` for values flushed to zero.
const SHEARED_RELATIVE: f32 = 1.0 / (1 << 17) as f32;
const SHEARED_SQUARED: f32 = 1.0 / (1u64 << 37) as f32;
const TINY: f32 = 1.0 / (1u128 << 100) as f32;

/// `end` moved by `2^-20` of itself and `2^-100` towards the sign of
/// `outwards`.
fn widened(end: f32, outwards: f32) -> f32 {
    end + outwards * (end.abs() * END_RELATIVE + END_ABSOLUTE)
}

//! Candidates behind the ray's origin, dropped from the triangle kernel's
//! own values: the triangle a secondary ray leaves is a candidate of nearly
//! every such ray (its origin sits just off that triangle, inside its
//! edges), and the scalar test would reject it only after the f64 plane
//! distance ([`crate::geometry::triangle`]'s `PlaneCrossing`). Here it is
//! dropped for all eight lanes at once, where the kernel can prove that
//! the scalar test rejects it: no answer changes.
//!
//! The proof. Take a lane the kernel finishes from its f32 edge functions
//! `e_i` (all of one sign, each beyond its error bound, so the exact ones
//! `ẽ_i` have that sign too), with `z_i` the f32 offsets of its corners
//! from the origin along `kz`. In exact arithmetic, Woop et al.'s sheared
//! distance `T̃ = Σ ẽ_i·z̃_i` is `±n` and their determinant `Σ ẽ_i` is
//! `±d / d_kz`, one sign for both, with `n = (p0 - o)·N`, `d = dir·N` and
//! `N = (p1 - p0) × (p2 - p0)`: the numerator and denominator the scalar
//! test evaluates in f64. So `t < 0` exactly when `T̃`'s sign differs from
//! that of `det·d_kz`. The kernel computes `T = Σ e_i·z_i` in f32 and
//! drops the lane when `T` has that other sign by more than a margin that
//! covers
//!
//! - the error of `T`: with `Z = max |z_i|`, `B` a bound on every
//!   `|e_i - ẽ_i|` and `Σ|e_i| = |Σ e_i|` (one sign), it is below
//!   `4.2u·Z·|det| + 3.1·B·Z` plus a few `f32::MIN_POSITIVE` times
//!   `|det| + B` (products and offsets flushed to zero); the margin takes
//!   `2^-20·Z·|det| + 4·B·Z`, and lanes with `Z < 2^-100`, where the
//!   flushes are not covered, are left to the scalar test;
//! - the scalar test's f64 evaluation: with `m` at least every corner's L1
//!   distance to the origin, `n` is computed within `2^-48·m³` and `d`
//!   within `2^-48·|d_kz|·m²` (eight roundings of 2^-53 over terms of at
//!   most `m·(2m)²`); the margin adds `2^-40·m³`, and the lane must have
//!   `|det| >= 4·B + 2^-40·m² + 2^-99`, so both f64 values have the exact
//!   signs, within 2^-7 of the exact values;
//! - the scalar test's threshold `|n| >= 2^-100·|d|` (`behind_origin`):
//!   `|d| <= 2.1·|det|·|d_kz|`, so the margin adds `2^-96·|det|·|d_kz|`;
//! - and `2^-99`, more than every flush of the margin's own terms (each
//!   product is formed so that a flushed one was below `MIN_POSITIVE`
//!   exactly) and of the error's absolute parts.
//!
//! The margin's constants are at least twice what the terms need, which
//! also covers its own rounding. `B` is the kernel's edge bound with the
//! lane's own distance `m` in place of the tree's reach: `m` is
//! `(max(|X|+|Y|) + 3·Z)·(1 + 2^-16)`, at least every corner's L1
//! distance (`|a_kx| <= |X| + |a_kz|` as the shear is at most 1). The
//! scalar test then rejects the lane as behind the origin, for any segment
//! starting at `t >= 0`; the kernel applies this only to those.

use super::lanes::LaneMask;
use crate::geometry::triangle::{ABSOLUTE_ERROR, RELATIVE_ERROR, UNDERFLOW_WEIGHT};
use std::arch::x86_64::*;

/// A block's lanes as the triangle kernel computed them.
pub(super) struct ShearedLanes {
    /// The edge functions `e_i`.
    pub edges: [__m256; 3],
    /// The corners' offsets `z_i` from the origin along `kz`.
    pub offsets: [__m256; 3],
    /// The smallest and largest offset.
    pub lowest_offset: __m256,
    pub highest_offset: __m256,
    /// The largest sheared magnitude `|X| + |Y|` of the corners.
    pub magnitude: __m256,
}

/// The direction's component along `kz`, as the margin takes it.
#[derive(Clone, Copy, Debug)]
pub(super) struct AlongKz {
    /// `|d_kz|`.
    pub length: f32,
    /// The sign bit of `d_kz`, as `-0.0` or `0.0`.
    pub sign: f32,
}

/// The lanes of `lanes` (those the kernel finishes from their edges) that
/// the scalar test would reject as behind the origin; see the module.
///
/// # Safety
/// Only inlined into code compiled for AVX2, on CPUs that have it.
#[inline(always)]
pub(super) unsafe fn behind_origin(lanes: &ShearedLanes, kz: AlongKz) -> LaneMask {
    // SAFETY: AVX is enabled where this is inlined.
    unsafe {
        let splat = _mm256_set1_ps;
        let sign_bit = splat(-0.0);
        let [e0, e1, e2] = lanes.edges;
        let [z0, z1, z2] = lanes.offsets;
        let det = _mm256_add_ps(_mm256_add_ps(e0, e1), e2);
        let distance = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(e0, z0), _mm256_mul_ps(e1, z1)),
            _mm256_mul_ps(e2, z2),
        );
        let abs_det = _mm256_andnot_ps(sign_bit, det);
        let z = _mm256_max_ps(
            lanes.highest_offset,
            _mm256_xor_ps(lanes.lowest_offset, sign_bit),
        );
        // The lane's own L1 distance bound and edge bound.
        let m = _mm256_mul_ps(
            _mm256_add_ps(lanes.magnitude, _mm256_mul_ps(z, splat(3.0))),
            splat(1.0 + 1.0 / 65536.0),
        );
        let weight = _mm256_add_ps(
            lanes.magnitude,
            _mm256_add_ps(
                _mm256_mul_ps(m, splat(RELATIVE_ERROR)),
                splat(UNDERFLOW_WEIGHT),
            ),
        );
        let bound = _mm256_add_ps(
            _mm256_mul_ps(_mm256_mul_ps(m, splat(2.0 * RELATIVE_ERROR)), weight),
            splat(ABSOLUTE_ERROR),
        );
        let m_squared = _mm256_mul_ps(m, m);
        let margin = _mm256_add_ps(
            _mm256_add_ps(
                _mm256_mul_ps(_mm256_mul_ps(z, abs_det), splat(1.0 / (1u64 << 20) as f32)),
                _mm256_mul_ps(_mm256_mul_ps(z, bound), splat(4.0)),
            ),
            _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(_mm256_mul_ps(m_squared, m), splat(2f32.powi(-40))),
                    _mm256_mul_ps(
                        _mm256_mul_ps(abs_det, splat(kz.length)),
                        splat(2f32.powi(-96)),
                    ),
                ),
                splat(2f32.powi(-99)),
            ),
        );
        // `T` with the sign of `det·d_kz` taken out: negative means behind.
        let sign = _mm256_and_ps(_mm256_xor_ps(det, splat(kz.sign)), sign_bit);
        let signed = _mm256_xor_ps(distance, sign);
        let behind = _mm256_cmp_ps::<_CMP_LT_OQ>(signed, _mm256_xor_ps(margin, sign_bit));
        let decided_det = _mm256_cmp_ps::<_CMP_GE_OQ>(
            abs_det,
            _mm256_add_ps(
                _mm256_add_ps(
                    _mm256_mul_ps(bound, splat(4.0)),
                    _mm256_mul_ps(m_squared, splat(2f32.powi(-40))),
                ),
                splat(2f32.powi(-99)),
            ),
        );
        let offsets_normal = _mm256_cmp_ps::<_CMP_GE_OQ>(z, splat(2f32.powi(-100)));
        _mm256_movemask_ps(_mm256_and_ps(
            behind,
            _mm256_and_ps(decided_det, offsets_normal),
        )) as LaneMask
    }
}

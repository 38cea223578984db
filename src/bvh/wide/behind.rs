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
use super::vector::Floats;
use crate::geometry::triangle::{ABSOLUTE_ERROR, RELATIVE_ERROR, UNDERFLOW_WEIGHT};

/// A block's lanes as the triangle kernel computed them.
pub(super) struct ShearedLanes<V> {
    /// The edge functions `e_i`.
    pub edges: [V; 3],
    /// The corners' offsets `z_i` from the origin along `kz`.
    pub offsets: [V; 3],
    /// The smallest and largest offset.
    pub lowest_offset: V,
    pub highest_offset: V,
    /// The largest sheared magnitude `|X| + |Y|` of the corners.
    pub magnitude: V,
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
/// Only inlined into code compiled for `V`'s instruction set
/// (`vector.rs`).
#[inline(always)]
pub(super) fn behind_origin<V: Floats>(lanes: &ShearedLanes<V>, kz: AlongKz) -> LaneMask {
    let splat = V::splat;
    let sign_bit = splat(-0.0);
    let [e0, e1, e2] = lanes.edges;
    let [z0, z1, z2] = lanes.offsets;
    let det = e0.add(e1).add(e2);
    let distance = e0.mul(z0).add(e1.mul(z1)).add(e2.mul(z2));
    let abs_det = det.abs();
    let z = lanes.highest_offset.max(lanes.lowest_offset.xor(sign_bit));
    // The lane's own L1 distance bound and edge bound.
    let m = lanes
        .magnitude
        .add(z.mul(splat(3.0)))
        .mul(splat(1.0 + 1.0 / 65536.0));
    let weight = lanes
        .magnitude
        .add(m.mul(splat(RELATIVE_ERROR)).add(splat(UNDERFLOW_WEIGHT)));
    let bound = m
        .mul(splat(2.0 * RELATIVE_ERROR))
        .mul(weight)
        .add(splat(ABSOLUTE_ERROR));
    let m_squared = m.mul(m);
    let margin = z
        .mul(abs_det)
        .mul(splat(1.0 / (1u64 << 20) as f32))
        .add(z.mul(bound).mul(splat(4.0)))
        .add(
            m_squared
                .mul(m)
                .mul(splat(2f32.powi(-40)))
                .add(abs_det.mul(splat(kz.length)).mul(splat(2f32.powi(-96))))
                .add(splat(2f32.powi(-99))),
        );
    // `T` with the sign of `det·d_kz` taken out: negative means behind.
    let sign = det.xor(splat(kz.sign)).and(sign_bit);
    let signed = distance.xor(sign);
    let behind = signed.lt(margin.xor(sign_bit));
    let decided_det = abs_det.ge(bound
        .mul(splat(4.0))
        .add(m_squared.mul(splat(2f32.powi(-40))))
        .add(splat(2f32.powi(-99))));
    let offsets_normal = z.ge(splat(2f32.powi(-100)));
    V::bits(V::both(behind, V::both(decided_det, offsets_normal)))
}

//! Where a closest-hit ray meets the planes of a block's eight triangles,
//! made for all eight lanes at once when a SIMD kernel leaves any lane of
//! the block inside ([`super::lanes::TriangleLanes`]).
//!
//! Each lane's numerator and denominator take the operations of
//! [`WatertightRay::plane_crossing`] in its order (f64, no fused
//! multiply-add) and its distance is their quotient, as
//! [`PlaneCrossing::distance`]'s, so the finished hits keep their bits;
//! the kernel-equality tests hold every kernel to the scalar test's. What
//! that pays for is not instructions
//! (more than the one or two lanes finished take one by one) but the wait:
//! made from a lane's corners once the kernel had picked the lane, a hit's
//! f64 distance and its division were one long chain after the edge tests;
//! made from the whole block's rows, they run beside them
//! (docs/performance.md, "Against Embree, part by part").

use super::node::{BLOCK_WIDTH, TriangleBlock};
#[cfg(doc)]
use crate::geometry::triangle::PlaneCrossing;
use crate::geometry::triangle::WatertightRay;

/// The distances to the planes of one block's lanes (padding lanes' NaN,
/// never read). Only the distance: a lane's crossing behind the origin,
/// which the scalar test rejects before dividing, has a distance that
/// rounds below the segment's start, which rejects it as surely.
#[repr(C, align(32))]
pub(super) struct BlockCrossings {
    distances: [f64; BLOCK_WIDTH],
}

impl BlockCrossings {
    /// Lane `lane`'s distance.
    #[inline(always)]
    pub fn distance(&self, lane: usize) -> f64 {
        self.distances[lane]
    }
}

/// The crossings of `ray` with every lane of `block`, four lanes to a
/// 256-bit register; only ever inlined into traversals compiled for AVX2
/// (the AVX2 and AVX-512 kernels).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) fn block_crossings(block: &TriangleBlock, ray: &WatertightRay) -> BlockCrossings {
    use std::arch::x86_64::*;
    let mut out = BlockCrossings {
        distances: [0.0; BLOCK_WIDTH],
    };
    let c = &block.corners;
    // SAFETY: AVX is enabled where this is inlined; each load reads four
    // f32 of one corner row (32 bytes long) from lane 0 or 4, each store
    // four f64 of one 32-byte-aligned row of `out` from lane 0 or 4.
    unsafe {
        // Macros, not closures: a closure is a function of its own,
        // compiled without the target features.
        macro_rules! splat {
            ($v:expr) => {{
                let v = $v;
                [v.x, v.y, v.z].map(|x| _mm256_set1_pd(f64::from(x)))
            }};
        }
        let [ox, oy, oz] = splat!(ray.origin());
        let [dx, dy, dz] = splat!(ray.direction());
        for first in [0, BLOCK_WIDTH / 2] {
            macro_rules! row {
                ($corner:expr, $axis:expr) => {
                    _mm256_cvtps_pd(_mm_loadu_ps(c[$corner][$axis].as_ptr().add(first)))
                };
            }
            let (x0, y0, z0) = (row!(0, 0), row!(0, 1), row!(0, 2));
            // The normal `(p1 - p0) × (p2 - p0)` and the dot products as
            // `DVec3::cross` and `DVec3::dot` make them.
            let (ax, ay, az) = (
                _mm256_sub_pd(row!(1, 0), x0),
                _mm256_sub_pd(row!(1, 1), y0),
                _mm256_sub_pd(row!(1, 2), z0),
            );
            let (bx, by, bz) = (
                _mm256_sub_pd(row!(2, 0), x0),
                _mm256_sub_pd(row!(2, 1), y0),
                _mm256_sub_pd(row!(2, 2), z0),
            );
            let nx = _mm256_sub_pd(_mm256_mul_pd(ay, bz), _mm256_mul_pd(by, az));
            let ny = _mm256_sub_pd(_mm256_mul_pd(az, bx), _mm256_mul_pd(bz, ax));
            let nz = _mm256_sub_pd(_mm256_mul_pd(ax, by), _mm256_mul_pd(bx, ay));
            macro_rules! dot_normal {
                ($x:expr, $y:expr, $z:expr) => {
                    _mm256_add_pd(
                        _mm256_add_pd(_mm256_mul_pd($x, nx), _mm256_mul_pd($y, ny)),
                        _mm256_mul_pd($z, nz),
                    )
                };
            }
            let numerator = dot_normal!(
                _mm256_sub_pd(x0, ox),
                _mm256_sub_pd(y0, oy),
                _mm256_sub_pd(z0, oz)
            );
            let denominator = dot_normal!(dx, dy, dz);
            _mm256_store_pd(
                out.distances.as_mut_ptr().add(first),
                _mm256_div_pd(numerator, denominator),
            );
        }
    }
    out
}

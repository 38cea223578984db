//! The watertight ray/triangle test of Woop, Benthin and Wald, "Watertight
//! Ray/Triangle Intersection", JCGT 2(1), 2013.
//!
//! The ray is turned into a shear that maps it onto the +z axis from the
//! origin; each triangle is transformed by that shear and tested in 2D with
//! three edge functions. Adjacent triangles compute the edge function of their
//! shared edge from the same sheared vertices, so the two values are exact
//! negations of each other and a ray can never slip between them.
//!
//! The f32 edge functions carry rounding error (the shear, the products), so
//! close to an edge their sign may differ from the exact one for the inputs
//! as given. An edge function within its error bound (`edge_error_bound`)
//! takes its sign from the exact predicate instead ([`crate::exact::edge_sign`],
//! Shewchuk 1997). The bound depends only on the edge's two corners, so the
//! two triangles sharing an edge take the same path and get opposite signs:
//! the test stays watertight, and agrees with the exact answer everywhere.
//! Which path decides a sign never changes the result (a valid bound only
//! lets through f32 signs that are the exact ones), so the bound is as tight
//! as the error analysis allows: every edge it leaves undecided costs an
//! exact evaluation.
//!
//! Before any of that, a triangle lying wholly before `tnear` or beyond
//! `tfar` along the ray's dominant axis is a miss ([`Segment`]): a cheap,
//! exact test that spares most candidates of a shadow ray the distance
//! computation.

use super::ray::Ray;
use crate::exact::edge_sign;
use glam::{Vec3, Vec3A};
use std::cmp::Ordering;

/// `8u`, with `u = 2^-24` the f32 unit roundoff: the relative factor of
/// [`edge_error_bound`].
///
/// A sheared coordinate `X = a_kx - s·a_kz` (with `|s| <= 1`, `kz` being
/// the dominant axis) is off from its exact value by at most
/// `γ4·(|a_kx| + |a_kz|) <= γ4·m`, `m` the corner's L1 distance to the ray
/// origin. An edge function `X_p·Y_q - Y_p·X_q` then errs by at most
/// `γ2·h_p·h_q + γ4·(h_p·m_q + h_q·m_p) + 2γ4²·m_p·m_q`, with
/// `h = |X| + |Y| <= 2m` (Higham's `γ_k = ku/(1-ku)`, pbrt-v4 section
/// 6.8.1). That is below `6u·(h_p·m_q + h_q·m_p) + 32u²·m_p·m_q`; `8u` and
/// the `8u·m` in each corner's weight ([`corner_weight`]) cover it and the
/// rounding of the bound itself.
pub(crate) const RELATIVE_ERROR: f32 = 4.0 * f32::EPSILON;

/// Added to each corner's weight so that [`RELATIVE_ERROR`] times it covers
/// `8·f32::MIN_POSITIVE` per unit of `m`: the error of coordinates flushed
/// to zero (the render workers run with FTZ/DAZ) carried through the
/// products. `2^-102 = MIN_POSITIVE / u`.
pub(crate) const UNDERFLOW_WEIGHT: f32 = f32::MIN_POSITIVE / (0.5 * f32::EPSILON);

/// Absolute part of [`edge_error_bound`]: results flushed to zero in the
/// edge function and in the bound itself, a few of `f32::MIN_POSITIVE` each.
pub(crate) const ABSOLUTE_ERROR: f32 = 16.0 * f32::MIN_POSITIVE;

/// A corner's weight in the error bound of the edges it ends: its sheared
/// magnitude `|X| + |Y|` plus `RELATIVE_ERROR·m` for the second-order
/// term and [`UNDERFLOW_WEIGHT`].
fn corner_weight(x: f32, y: f32, m: f32) -> f32 {
    (x.abs() + y.abs()) + (RELATIVE_ERROR * m + UNDERFLOW_WEIGHT)
}

/// The bound on the rounding error of the edge function of corners `p`,
/// `q`, from their weights `w` ([`corner_weight`]) and L1 distances `m` to
/// the ray origin. Symmetric in `p` and `q` bit for bit (only commutative
/// operations combine them), so both triangles sharing an edge compute the
/// same bound. The SIMD kernels (`bvh::wide::simd`) bound all three edges of
/// a triangle with one larger value.
fn edge_error_bound(w_p: f32, m_p: f32, w_q: f32, m_q: f32) -> f32 {
    RELATIVE_ERROR * (w_p * m_q + w_q * m_p) + ABSOLUTE_ERROR
}

/// The L1 length `|x| + |y| + |z|` of a corner relative to the ray origin,
/// summed in that order.
fn l1_length(v: Vec3) -> f32 {
    (v.x.abs() + v.y.abs()) + v.z.abs()
}

/// A ray prepared for the watertight test (the per-ray part of Woop et al.
/// 2013, section 3): the axis of the largest direction component `kz`, the
/// other two axes `kx`, `ky` (swapped when `dir[kz] < 0` to keep the winding),
/// and the shear constants.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    origin: Vec3,
    direction: Vec3,
    kx: usize,
    ky: usize,
    kz: usize,
    shear_x: f32,
    shear_y: f32,
    /// The direction along `[kx, ky, kz]`.
    direction_along_axes: Vec3A,
}

/// The part `[tnear, tfar]` of a ray that the test looks for hits in, and
/// the box it spans: its window along each axis of the ray space.
///
/// A point of the ray's line at parameter `t` has `p[k] - o[k] = t·d[k]`
/// along every axis `k`, and every point of a triangle lies between its
/// corners along `k`. So when the three corners' offsets `p[k] - o[k]` all
/// lie below `below[i]`, or all above `above[i]`, along any axis `k` of
/// `[kx, ky, kz]` (index `i`), every point where the line meets the
/// triangle is outside `[tnear, tfar]`: a miss. The windows' ends are
/// `tnear·d[k]` and `tfar·d[k]` (swapped for a negative `d[k]`) moved
/// outwards (`windows`) by more than the rounding, or the flush to zero,
/// of an f32 distance to an end can move it, so a hit whose distance rounds
/// to an end is not dropped. The offsets are compared as computed in f32:
/// rounding is monotone, so an offset that rounds beyond an f32 bound is
/// beyond it exactly, with or without flush-to-zero. The SIMD kernels
/// (`bvh::wide::simd`) compute the same offsets along `kz` and compare
/// them with the same bounds; what the other two windows would drop, the
/// distance rejects as the kernels finish a lane, with the same answer.
/// Along `kz` the window drops most triangles behind a hit;
/// along `kx` and `ky` it drops large triangles the line crosses beyond
/// either end, as the walls and ceiling a shadow ray points at in a room.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub tnear: f32,
    pub tfar: f32,
    /// Per axis of `[kx, ky, kz]`, offsets below this are outside the
    /// segment.
    pub below: [f32; 3],
    /// Per axis of `[kx, ky, kz]`, offsets above this are outside the
    /// segment.
    pub above: [f32; 3],
}

/// The windows `(below, above)` of offsets `t·d` over `t` in `[tnear,
/// tfar]` along the axes where the direction is `d` (see [`Segment`]), all
/// three at once in f32: each end is `t·d`, rounded, moved outwards by
/// `2^-19·|t·d|`, many times an f32 ulp of it (an f32 distance's rounding,
/// and the product's own), and by `2^-99·(|d| + 1)`, more than
/// `f32::MIN_POSITIVE·|d|` (a distance flushed to zero). Each margin is
/// twice what the rounding of a distance needs, so the roundings of this
/// arithmetic (2^-24 relative each) cannot eat into it. Infinities stay;
/// NaN (∞ - ∞) passes no comparison. Unbounded along an axis where `d`
/// reads as 0, as a subnormal does with denormals-are-zero.
#[inline(always)]
fn windows(d: Vec3A, tnear: f32, tfar: f32) -> (Vec3A, Vec3A) {
    const RELATIVE: f32 = 1.0 / (1u32 << 19) as f32;
    const ABSOLUTE: f32 = 1.0 / (1u128 << 99) as f32;
    let (first, last) = (d * tnear, d * tfar);
    // By selects, not branches on the sign of `d`: for incoherent rays
    // each would be mispredicted every other ray.
    let negative = d.cmplt(Vec3A::ZERO);
    let low = Vec3A::select(negative, last, first);
    let high = Vec3A::select(negative, first, last);
    let absolute = (d.abs() + 1.0) * ABSOLUTE;
    let below = low - (low.abs() * RELATIVE + absolute);
    let above = high + (high.abs() * RELATIVE + absolute);
    let unbounded = d.cmpeq(Vec3A::ZERO);
    (
        Vec3A::select(unbounded, Vec3A::NEG_INFINITY, below),
        Vec3A::select(unbounded, Vec3A::INFINITY, above),
    )
}

/// Where a ray meets a triangle: `t` along the ray, and barycentrics in
/// Embree's convention (`u` weights `p1`, `v` weights `p2`). Without the
/// triangle's normal: a closest-hit search makes [`geometric_normal`] for
/// the candidates that become its best, not for every one it finishes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    /// `t` before its rounding to f32: it orders two hits whose `t` round
    /// to the same f32 (a ray meeting two surfaces less than an ulp apart),
    /// where the f32 values alone would leave the nearer one to chance.
    pub distance: f64,
}

impl WatertightRay {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        // Plain arrays and selects: indexing a vector by a run-time axis,
        // or a table of axes, costs branches and stores on every ray.
        let d = ray.dir.to_array();
        let [x, y, z] = d.map(f32::abs);
        // x if it is the largest, else y if it is at least z, else z; as
        // arithmetic, since the dominant axis of incoherent rays is
        // unpredictable and a mispredicted branch costs more.
        let not_x = usize::from(!(x >= y && x >= z));
        let kz = not_x * (2 - usize::from(y >= z));
        // The next two axes in cyclic order.
        const NEXT: [usize; 3] = [1, 2, 0];
        const AFTER_NEXT: [usize; 3] = [2, 0, 1];
        let (kx, ky) = (NEXT[kz], AFTER_NEXT[kz]);
        let dz = d[kz];
        let (kx, ky) = if dz < 0.0 { (ky, kx) } else { (kx, ky) };
        Self {
            origin: ray.origin,
            direction: ray.dir,
            kx,
            ky,
            kz,
            shear_x: d[kx] / dz,
            shear_y: d[ky] / dz,
            direction_along_axes: Vec3A::new(d[kx], d[ky], dz),
        }
    }

    /// The ray's origin, for kernels that evaluate the same edge functions
    /// on several triangles at once.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The ray's direction, for kernels that make the plane crossings of
    /// several triangles at once.
    pub fn direction(&self) -> Vec3 {
        self.direction
    }

    /// The axes `[kx, ky, kz]` of the ray space (`kz` the dominant one).
    pub fn axes(&self) -> [usize; 3] {
        [self.kx, self.ky, self.kz]
    }

    /// `dir[kz]`, the direction's dominant component.
    pub fn direction_kz(&self) -> f32 {
        self.direction_along_axes.z
    }

    /// The shear constants `[dir[kx] / dir[kz], dir[ky] / dir[kz]]`.
    pub fn shear(&self) -> [f32; 2] {
        [self.shear_x, self.shear_y]
    }

    /// The part `[tnear, tfar]` of this ray, with its windows along
    /// `[kx, ky, kz]`.
    #[inline(always)]
    pub fn segment(&self, tnear: f32, tfar: f32) -> Segment {
        let (below, above) = windows(self.direction_along_axes, tnear, tfar);
        Segment {
            tnear,
            tfar,
            below: below.to_array(),
            above: above.to_array(),
        }
    }

    /// Whether triangle `(p0, p1, p2)` lies wholly outside `segment`'s
    /// window along one of the axes (see [`Segment`]); never for a NaN
    /// corner.
    #[inline(always)]
    pub fn outside(&self, p0: Vec3, p1: Vec3, p2: Vec3, segment: &Segment) -> bool {
        let origin = self.origin.to_array();
        let corners = [p0, p1, p2].map(|p| p.to_array());
        let beyond = |i: usize, k: usize| {
            let offsets = corners.map(|p| p[k] - origin[k]);
            offsets.iter().all(|&a| a < segment.below[i])
                || offsets.iter().all(|&a| a > segment.above[i])
        };
        // `kz` first: along it the window is tightest.
        beyond(2, self.kz) || beyond(0, self.kx) || beyond(1, self.ky)
    }

    /// The hit with triangle `(p0, p1, p2)` if `tnear <= t <= tfar`:
    /// [`WatertightRay::intersect_in`] over [`WatertightRay::segment`].
    pub fn intersect(
        &self,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
        tnear: f32,
        tfar: f32,
    ) -> Option<TriangleHit> {
        self.intersect_in(p0, p1, p2, &self.segment(tnear, tfar))
    }

    /// The hit with triangle `(p0, p1, p2)` within `segment`.
    ///
    /// Both faces are hit (no backface culling); a degenerate triangle
    /// (determinant or geometric normal exactly 0) is never hit; any NaN in
    /// the ray or triangle gives no hit.
    pub fn intersect_in(
        &self,
        p0: Vec3,
        p1: Vec3,
        p2: Vec3,
        segment: &Segment,
    ) -> Option<TriangleHit> {
        if self.outside(p0, p1, p2, segment) {
            return None;
        }
        let (mut edges, bounds) = self.edge_functions(p0, p1, p2);
        let mut signs = edges.map(|e| e.partial_cmp(&0.0).unwrap_or(Ordering::Equal));
        let ends = [(p2, p1), (p0, p2), (p1, p0)];
        for i in 0..3 {
            if edges[i].abs() <= bounds[i] {
                let (p, q) = ends[i];
                let exact = edge_sign(
                    &self.origin.to_array(),
                    &self.direction.to_array(),
                    &p.to_array(),
                    &q.to_array(),
                );
                // A value of the wrong sign is within the bound of 0.
                if exact != signs[i] {
                    edges[i] = 0.0;
                }
                signs[i] = exact;
            }
        }

        if signs.contains(&Ordering::Less) && signs.contains(&Ordering::Greater) {
            return None;
        }
        let hit = self.finish(edges, segment, || {
            let crossing = self.plane_crossing(p0, p1, p2);
            // The triangle a secondary ray leaves is a candidate of nearly
            // every such ray, behind its origin: no division for it (its
            // distance would round below `tnear`, which the finish rejects).
            let behind = segment.tnear >= 0.0 && crossing.behind_origin();
            (!behind).then(|| crossing.distance())
        })?;
        // Rounding in the shear can leave a tiny nonzero determinant for a
        // triangle whose corners are collinear, so a zero geometric normal
        // also counts as degenerate (tested last, on the rare path of a
        // candidate hit).
        (geometric_normal(p0, p1, p2) != Vec3::ZERO).then_some(hit)
    }

    /// The edge functions of triangle `(p0, p1, p2)` in ray space, each
    /// weighting the vertex opposite its edge, and their error bounds.
    fn edge_functions(&self, p0: Vec3, p1: Vec3, p2: Vec3) -> ([f32; 3], [f32; 3]) {
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let a = p0 - self.origin;
        let b = p1 - self.origin;
        let c = p2 - self.origin;
        let ax = a[kx] - self.shear_x * a[kz];
        let ay = a[ky] - self.shear_y * a[kz];
        let bx = b[kx] - self.shear_x * b[kz];
        let by = b[ky] - self.shear_y * b[kz];
        let cx = c[kx] - self.shear_x * c[kz];
        let cy = c[ky] - self.shear_y * c[kz];
        let edges = [cx * by - cy * bx, ax * cy - ay * cx, bx * ay - by * ax];
        let [ma, mb, mc] = [a, b, c].map(l1_length);
        let [wa, wb, wc] =
            [(ax, ay, ma), (bx, by, mb), (cx, cy, mc)].map(|(x, y, m)| corner_weight(x, y, m));
        let bounds = [
            edge_error_bound(wc, mc, wb, mb),
            edge_error_bound(wa, ma, wc, mc),
            edge_error_bound(wb, mb, wa, ma),
        ];
        (edges, bounds)
    }

    /// The rest of [`WatertightRay::intersect_in`] once the triangle is
    /// known not to be [`WatertightRay::outside`] the segment and the signs
    /// of the edge functions are decided and not mixed: `edges` are the f32
    /// values `intersect_in` computes, each set to 0 where its exact sign
    /// differs, and `distance` the [`PlaneCrossing::distance`] of the
    /// triangle's [`WatertightRay::plane_crossing`]. SIMD kernels that decide
    /// the signs of several triangles at once, and make their distances
    /// together (`bvh::wide::crossings`), finish each candidate here, so
    /// they return the same bits.
    ///
    /// All but the test of the geometric normal, which `intersect_in` adds
    /// last: for triangles whose [`geometric_normal`] is not zero, as every
    /// triangle a tree stores (`bvh::build::usable_corners`). Made here for
    /// every candidate, before the distance, the normal and its test left
    /// the Cornell box's diffuse rays 7-8% slower (AMD EPYC, both kernels;
    /// `docs/performance.md`).
    #[inline(always)]
    pub fn hit_within_edges(
        &self,
        edges: [f32; 3],
        distance: f64,
        segment: &Segment,
    ) -> Option<TriangleHit> {
        self.finish(edges, segment, || Some(distance))
    }

    /// Where this ray's line meets the plane of triangle `(p0, p1, p2)`.
    #[inline(always)]
    pub fn plane_crossing(&self, p0: Vec3, p1: Vec3, p2: Vec3) -> PlaneCrossing {
        PlaneCrossing::new(p0, p1, p2, self.origin, self.direction)
    }

    /// [`WatertightRay::hit_within_edges`], with the distance from
    /// `distance`, asked for only for a determinant that is not 0; `None`
    /// for a triangle it knows the segment misses.
    #[inline(always)]
    fn finish(
        &self,
        edges: [f32; 3],
        segment: &Segment,
        distance: impl FnOnce() -> Option<f64>,
    ) -> Option<TriangleHit> {
        let [e0, e1, e2] = edges;
        let det = e0 + e1 + e2;
        // Also rejects a NaN determinant.
        if !(det != 0.0 && det.is_finite()) {
            return None;
        }
        let distance = distance()?;
        let t = distance as f32;
        // Inclusive at both ends, as Embree's robust mode; false for NaN.
        if !(t >= segment.tnear && t <= segment.tfar && t.is_finite()) {
            return None;
        }
        Some(TriangleHit {
            t,
            u: e1 / det,
            v: e2 / det,
            distance,
        })
    }
}

impl TriangleHit {
    /// Whether this hit is nearer than `other`: by the unrounded distance,
    /// then by the lower prim id, so the closest hit never depends on the
    /// order the triangles were tested in.
    pub fn nearer_than(&self, prim: u32, other: &TriangleHit, other_prim: u32) -> bool {
        (self.distance, prim) < (other.distance, other_prim)
    }
}

/// Where the ray meets the triangle's plane: the ray parameter
/// `(p0 - o)·n / (d·n)` with `n = (p1 - p0) × (p2 - p0)`, its numerator and
/// denominator evaluated in f64 (the caller rounds the distance once to
/// f32, and keeps it to order near ties).
///
/// The sheared form of Woop et al. (`Σ e_i·z_i / det`) subtracts products of
/// the vertices' distances from the origin, so a hit much closer to the
/// origin than the vertices are (a secondary ray leaving a wall and meeting
/// the floor next to it) loses most of its relative precision in `t`. The
/// scalar test makes it only for candidate hits, and the SIMD kernels only
/// for blocks holding one (`bvh::wide::crossings`), so the f64 cost is
/// small.
#[derive(Clone, Copy, Debug)]
pub struct PlaneCrossing {
    numerator: f64,
    denominator: f64,
}

impl PlaneCrossing {
    #[inline(always)]
    fn new(p0: Vec3, p1: Vec3, p2: Vec3, origin: Vec3, direction: Vec3) -> Self {
        let [p0, p1, p2, origin, direction] = [p0, p1, p2, origin, direction].map(Vec3::as_dvec3);
        let normal = (p1 - p0).cross(p2 - p0);
        PlaneCrossing {
            numerator: (p0 - origin).dot(normal),
            denominator: direction.dot(normal),
        }
    }

    /// Whether the distance is certainly negative once rounded to f32,
    /// without dividing: numerator and denominator of opposite signs (both
    /// nonzero), and the quotient at least `2^-100` in magnitude, so its
    /// f64 and then f32 roundings stay negative and normal.
    #[inline(always)]
    fn behind_origin(&self) -> bool {
        const SMALLEST: f64 = 1.0 / (1u128 << 100) as f64;
        let (n, d) = (self.numerator, self.denominator);
        d != 0.0 && (n < 0.0) != (d < 0.0) && n.abs() >= d.abs() * SMALLEST
    }

    #[inline(always)]
    pub fn distance(&self) -> f64 {
        self.numerator / self.denominator
    }
}

/// The unnormalized geometric normal `(p1 - p0) × (p2 - p0)` (Embree's `Ng`).
pub fn geometric_normal(p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    (p1 - p0).cross(p2 - p0)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::exact::expansion::Expansion;
    use crate::random::Rng;

    fn hit(ray: Ray, tri: [Vec3; 3]) -> Option<TriangleHit> {
        WatertightRay::new(&ray).intersect(tri[0], tri[1], tri[2], ray.tnear, ray.tfar)
    }

    const UNIT: [Vec3; 3] = [Vec3::ZERO, Vec3::X, Vec3::Y];

    #[test]
    fn interior_hit_has_known_t_and_barycentrics() {
        // (0.25, 0.5) = 0.25·p1 + 0.5·p2 on the unit triangle at z = 0.
        let ray = Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::new(0.0, 0.0, -1.0));
        let h = hit(ray, UNIT).expect("interior hit");
        assert_eq!(
            h,
            TriangleHit {
                t: 2.0,
                u: 0.25,
                v: 0.5,
                distance: 2.0,
            }
        );
        // The back face is hit too, with the same barycentrics.
        let below = Ray::new(Vec3::new(0.25, 0.5, -4.0), Vec3::new(0.0, 0.0, 2.0));
        assert_eq!(
            hit(below, UNIT),
            Some(TriangleHit {
                t: 2.0,
                u: 0.25,
                v: 0.5,
                distance: 2.0,
            })
        );
    }

    #[test]
    fn hit_point_matches_barycentrics_for_oblique_rays() {
        let mut rng = Rng::new(1);
        let mut hits = 0;
        for _ in 0..2000 {
            let tri = [
                rng.point(-1.0, 1.0),
                rng.point(-1.0, 1.0),
                rng.point(-1.0, 1.0),
            ];
            let (u, v) = (rng.unit_f32(), rng.unit_f32());
            let (u, v) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let target = (1.0 - u - v) * tri[0] + u * tri[1] + v * tri[2];
            let origin = rng.point(-3.0, 3.0);
            let Some(h) = hit(Ray::new(origin, target - origin), tri) else {
                continue;
            };
            hits += 1;
            let on_ray = origin + h.t * (target - origin);
            let on_tri = (1.0 - h.u - h.v) * tri[0] + h.u * tri[1] + h.v * tri[2];
            assert!((on_ray - on_tri).length() < 1e-3, "{on_ray} vs {on_tri}");
            assert!((h.t - 1.0).abs() < 1e-3, "t = {}", h.t);
        }
        // Rays aimed at interior points miss only for near-degenerate
        // triangles seen edge-on.
        assert!(hits > 1900, "only {hits} hits");
    }

    #[test]
    fn edges_and_vertices_are_hit() {
        let down = Vec3::new(0.0, 0.0, -1.0);
        for (x, y, u, v) in [
            (0.0, 0.0, 0.0, 0.0),
            (1.0, 0.0, 1.0, 0.0),
            (0.0, 1.0, 0.0, 1.0),
            (0.5, 0.0, 0.5, 0.0),
            (0.0, 0.5, 0.0, 0.5),
            (0.5, 0.5, 0.5, 0.5),
        ] {
            let h = hit(Ray::new(Vec3::new(x, y, 1.0), down), UNIT);
            assert_eq!(
                h,
                Some(TriangleHit {
                    t: 1.0,
                    u,
                    v,
                    distance: 1.0,
                }),
                "at ({x}, {y})"
            );
        }
        // Just outside each edge: a miss.
        for (x, y) in [(0.5, -1e-7), (-1e-7, 0.5), (0.5 + 1e-7, 0.5)] {
            assert_eq!(
                hit(Ray::new(Vec3::new(x, y, 1.0), down), UNIT),
                None,
                "at ({x}, {y})"
            );
        }
    }

    /// Orientation of `(b, c, d)` seen from `a`, in f64 (exact enough for a
    /// sign away from 0 at these magnitudes).
    fn orientation(a: Vec3, b: Vec3, c: Vec3, d: Vec3) -> f64 {
        let [b, c, d] = [b - a, c - a, d - a].map(|p| p.as_dvec3());
        b.cross(c).dot(d)
    }

    /// Woop et al.'s central claim: a ray through a shared edge hits at least
    /// one of the two triangles, whatever the rounding, as long as the two
    /// are on opposite sides of the edge as seen from the ray's origin (not a
    /// silhouette edge).
    #[test]
    fn shared_edges_are_watertight() {
        let mut rng = Rng::new(2);
        let mut tested = 0;
        while tested < 20_000 {
            let (p, q, r, s) = (
                rng.point(-10.0, 10.0),
                rng.point(-10.0, 10.0),
                rng.point(-10.0, 10.0),
                rng.point(-10.0, 10.0),
            );
            let origin = rng.point(-50.0, 50.0);
            let (first, second) = ([p, q, r], [q, p, s]);
            let facing = orientation(origin, p, q, r) * orientation(origin, q, p, s);
            if facing < 1e-3 {
                continue;
            }
            tested += 1;
            let on_edge = p.lerp(q, rng.unit_f32());
            let ray = Ray::new(origin, on_edge - origin);
            assert!(
                hit(ray, first).is_some() || hit(ray, second).is_some(),
                "ray {ray:?} leaks between {first:?} and {second:?}"
            );
        }
    }

    /// The two products of an edge function can round to the same f32 when
    /// they differ exactly; the f64 recomputation must then decide, so a ray
    /// passing a hair beside a shared edge hits exactly one triangle rather
    /// than both.
    #[test]
    fn edge_function_rounding_to_zero_is_resolved_exactly() {
        let (a, b) = (1.0 + 2f32.powi(-12), 1.0 + 2f32.powi(-11));
        // Exactly, A×B = -a·a + b = -2^-24, but a·a rounds to b in f32.
        let corner_a = Vec3::new(-a, -1.0, 0.0);
        let corner_b = Vec3::new(b, a, 0.0);
        let left = [corner_a, corner_b, Vec3::new(-1.0, 1.0, 0.0)];
        let right = [corner_b, corner_a, Vec3::new(1.0, -1.0, 0.0)];
        let ray = Ray::new(Vec3::Z, Vec3::NEG_Z);
        // The origin's projection (0, 0) is on the side of `right`.
        assert_eq!(hit(ray, left), None);
        assert!(hit(ray, right).is_some());
    }

    /// Rays aimed at corners and edge points, where the f32 edge functions
    /// are within their rounding error of 0: the hit decision is the exact
    /// one for the inputs as given.
    #[test]
    fn decisions_near_edges_are_exact() {
        let mut rng = Rng::new(5);
        let mut near_edge = 0;
        for _ in 0..20_000 {
            let tri = [
                rng.point(-1e3, 1e3),
                rng.point(-1e3, 1e3),
                rng.point(-1e3, 1e3),
            ];
            let origin = rng.point(-1e4, 1e4);
            let corner = (rng.next_u64() % 3) as usize;
            let target = tri[corner].lerp(
                tri[(corner + 1) % 3],
                rng.unit_f32().round() * rng.unit_f32(),
            );
            let ray = Ray::new(origin, target - origin);
            let [o, d] = [ray.origin, ray.dir].map(|v| v.to_array());
            let [p0, p1, p2] = tri.map(|p| p.to_array());
            let signs = [(p2, p1), (p0, p2), (p1, p0)].map(|(p, q)| edge_sign(&o, &d, &p, &q));
            let inside = !(signs.contains(&Ordering::Less) && signs.contains(&Ordering::Greater))
                && signs != [Ordering::Equal; 3];
            near_edge += usize::from(signs.contains(&Ordering::Equal) || !inside);
            assert_eq!(hit(ray, tri).is_some(), inside, "{ray:?} and {tri:?}");
        }
        assert!(near_edge > 1000, "only {near_edge} rays beside an edge");
    }

    /// The exact value of edge function `(p, q)` of the ray, times
    /// `dir[kz]²`: `U_p·V_q - V_p·U_q` with `U = a_kx·d_kz - d_kx·a_kz`,
    /// `V = a_ky·d_kz - d_ky·a_kz` and `a = corner - origin`, in expansions.
    fn exact_scaled_edge(ray: &Ray, axes: [usize; 3], p: Vec3, q: Vec3) -> Expansion {
        let [kx, ky, kz] = axes;
        let d = ray
            .dir
            .to_array()
            .map(|x| Expansion::from_f64(f64::from(x)));
        let sheared = |corner: Vec3| {
            let a: [Expansion; 3] = std::array::from_fn(|k| {
                Expansion::difference(f64::from(corner[k]), f64::from(ray.origin[k]))
            });
            let along = |k: usize| a[k].mul(&d[kz]).sub(&d[k].mul(&a[kz]));
            (along(kx), along(ky))
        };
        let ((up, vp), (uq, vq)) = (sheared(p), sheared(q));
        up.mul(&vq).sub(&vp.mul(&uq))
    }

    /// Every f32 edge function lies within its error bound of the exact
    /// value, at scales from 1e-6 to 1e6 and origins up to 1e4 sizes away,
    /// for rays aimed at edges and corners (where the values are smallest)
    /// and at interiors. The bound is what lets an f32 sign stand without
    /// the exact predicate, so a bound too small would be a wrong answer.
    #[test]
    fn edge_error_bounds_hold_at_every_scale() {
        let mut rng = Rng::new(6);
        let mut rounded = 0;
        for _ in 0..20_000 {
            let size = 10f32.powf(rng.range_f32(-6.0, 6.0));
            let centre = rng.point(-1.0, 1.0) * size * 10f32.powf(rng.range_f32(0.0, 3.0));
            let tri = [(); 3].map(|_| centre + rng.point(-size, size));
            let distance = size * 10f32.powf(rng.range_f32(0.0, 4.0));
            let origin = centre + rng.point(-distance, distance);
            let corner = rng.below(3);
            let along_edge = tri[corner].lerp(tri[(corner + 1) % 3], rng.unit_f32());
            let target = match rng.below(3) {
                0 => tri[corner],
                1 => along_edge,
                _ => along_edge.lerp(tri[(corner + 2) % 3], rng.unit_f32()),
            };
            let ray = Ray::new(origin, target - origin);
            let wray = WatertightRay::new(&ray);
            let (edges, bounds) = wray.edge_functions(tri[0], tri[1], tri[2]);
            let [p0, p1, p2] = tri;
            for (i, (p, q)) in [(p2, p1), (p0, p2), (p1, p0)].into_iter().enumerate() {
                let dz = Expansion::from_f64(f64::from(ray.dir[wray.axes()[2]]));
                let scale = dz.mul(&dz);
                let computed = Expansion::from_f64(f64::from(edges[i])).mul(&scale);
                let error = computed.sub(&exact_scaled_edge(&ray, wray.axes(), p, q));
                let allowed = Expansion::from_f64(f64::from(bounds[i])).mul(&scale);
                assert!(
                    allowed.sub(&error).sign() != Ordering::Less
                        && allowed.add(&error).sign() != Ordering::Less,
                    "edge {i} of {tri:?} for {ray:?}: {} beyond its bound {}",
                    edges[i],
                    bounds[i]
                );
                rounded += usize::from(error.sign() != Ordering::Equal);
            }
        }
        assert!(rounded > 10_000, "only {rounded} edge values were rounded");
    }

    #[test]
    fn shared_vertex_fan_is_watertight() {
        // A fan of triangles around the origin; rays aimed at the centre.
        let n = 7;
        let fan: Vec<[Vec3; 3]> = (0..n)
            .map(|i| {
                let angle = |k: usize| std::f32::consts::TAU * k as f32 / n as f32;
                let rim =
                    |k: usize| Vec3::new(angle(k).cos(), angle(k).sin(), 0.3 * (k % 2) as f32);
                [Vec3::ZERO, rim(i), rim((i + 1) % n)]
            })
            .collect();
        // Seen from within 45 degrees of the z axis, no face of this fan
        // hides another, so every ray aimed at the centre must hit.
        let mut rng = Rng::new(3);
        for _ in 0..5000 {
            let (x, y) = (rng.range_f32(-10.0, 10.0), rng.range_f32(-10.0, 10.0));
            let height = rng.range_f32(1.5, 3.0) * x.abs().max(y.abs()) + 0.1;
            let z = if rng.unit_f32() < 0.5 {
                height
            } else {
                -height
            };
            let origin = Vec3::new(x, y, z);
            let ray = Ray::new(origin, -origin);
            assert!(
                fan.iter().any(|&t| hit(ray, t).is_some()),
                "ray {ray:?} misses the fan centre"
            );
        }
    }

    #[test]
    fn parallel_ray_misses() {
        // In the triangle's plane, through its interior.
        let ray = Ray::new(Vec3::new(-1.0, 0.25, 0.0), Vec3::X);
        assert_eq!(hit(ray, UNIT), None);
        // Above the plane.
        let ray = Ray::new(Vec3::new(-1.0, 0.25, 0.5), Vec3::X);
        assert_eq!(hit(ray, UNIT), None);
    }

    #[test]
    fn grazing_rays_hit_near_the_plane() {
        // Almost parallel to the triangle's plane, crossing it inside.
        let dir = Vec3::new(1.0, 0.0, -1e-6);
        let ray = Ray::new(Vec3::new(-0.75, 0.25, 1e-6), dir);
        let h = hit(ray, UNIT).expect("grazing hit");
        assert!(
            (h.t - 1.0).abs() < 1e-5 && (h.u - 0.25).abs() < 1e-5 && (h.v - 0.25).abs() < 1e-5,
            "{h:?}"
        );
        // Same direction, crossing the plane beyond the triangle.
        let ray = Ray::new(Vec3::new(-3.0, 0.25, 1e-6), dir);
        assert_eq!(hit(ray, UNIT), None);
    }

    #[test]
    fn interval_bounds_are_inclusive() {
        let ray = |tnear, tfar| {
            Ray::segment(
                Vec3::new(0.25, 0.25, 1.0),
                Vec3::new(0.0, 0.0, -1.0),
                tnear,
                tfar,
            )
        };
        assert!(hit(ray(1.0, 1.0), UNIT).is_some());
        assert!(hit(ray(0.0, 1.0), UNIT).is_some());
        assert!(hit(ray(1.0, 2.0), UNIT).is_some());
        assert_eq!(
            hit(ray(0.0, f32::from_bits(1.0f32.to_bits() - 1)), UNIT),
            None
        );
        assert_eq!(
            hit(ray(f32::from_bits(1.0f32.to_bits() + 1), 2.0), UNIT),
            None
        );
        // Behind the origin.
        assert_eq!(hit(ray(-5.0, -2.0), UNIT), None);
        assert!(hit(ray(2.0, 1.0), UNIT).is_none());
    }

    /// The window along the dominant axis drops only what the distance
    /// test drops too: on random triangles and rays at scales from 1e-3 to
    /// 1e3, with segments ending exactly at, and one f32 step short of, a
    /// hit's distance, the test gives what it gives with no window (its
    /// hit within the interval, or none), and the window does drop the
    /// triangles wholly before or beyond the segment.
    #[test]
    fn the_window_drops_only_hits_outside_the_segment() {
        let mut rng = Rng::new(4);
        let (mut cases, mut dropped) = (0, 0);
        while cases < 20_000 {
            let scale = 10f32.powf(rng.range_f32(-3.0, 3.0));
            let [p0, p1, p2] = [(); 3].map(|_| rng.point(-1.0, 1.0) * scale);
            let target = p0.lerp(p1, rng.unit_f32()).lerp(p2, rng.unit_f32());
            let origin = rng.point(-4.0, 4.0) * scale;
            let ray = Ray::new(origin, (target - origin) * rng.range_f32(0.1, 10.0));
            let wray = WatertightRay::new(&ray);
            let no_window = |tnear: f32, tfar: f32| Segment {
                tnear,
                tfar,
                below: [f32::NEG_INFINITY; 3],
                above: [f32::INFINITY; 3],
            };
            let line = no_window(f32::NEG_INFINITY, f32::INFINITY);
            let Some(free) = wray.intersect_in(p0, p1, p2, &line) else {
                continue;
            };
            cases += 1;
            let (t, before, after) = (free.t, free.t.next_down(), free.t.next_up());
            for (tnear, tfar) in [
                (t, t),
                (0.0, t),
                (t, f32::INFINITY),
                (0.0, before),
                (after, f32::INFINITY),
                (f32::NEG_INFINITY, 0.5 * t - scale),
                (1.5 * t + scale, f32::INFINITY),
            ] {
                let expected = wray.intersect_in(p0, p1, p2, &no_window(tnear, tfar));
                assert_eq!(
                    wray.intersect(p0, p1, p2, tnear, tfar),
                    expected,
                    "[{tnear}, {tfar}] of {ray:?} on {:?}",
                    [p0, p1, p2]
                );
                dropped += usize::from(wray.outside(p0, p1, p2, &wray.segment(tnear, tfar)));
            }
        }
        assert!(dropped > 10_000, "the window dropped only {dropped}");
    }

    #[test]
    fn a_wall_beyond_the_segments_end_is_outside_it_across_the_ray() {
        // Dominant axis x; the wall at y = 2 spans the whole window along x,
        // but the segment [0, 1] only reaches y = 0.5.
        let ray = Ray::segment(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.0), 0.0, 1.0);
        let wray = WatertightRay::new(&ray);
        assert_eq!(wray.axes()[2], 0);
        let wall = [
            Vec3::new(-10.0, 2.0, -10.0),
            Vec3::new(10.0, 2.0, -10.0),
            Vec3::new(0.0, 2.0, 10.0),
        ];
        let [p0, p1, p2] = wall;
        assert!(wray.intersect(p0, p1, p2, 0.0, f32::INFINITY).is_some());
        let segment = wray.segment(0.0, 1.0);
        assert!(wray.outside(p0, p1, p2, &segment));
        // Only across the ray: along kz alone the wall is inside.
        let along_kz_only = Segment {
            below: [f32::NEG_INFINITY, f32::NEG_INFINITY, segment.below[2]],
            above: [f32::INFINITY, f32::INFINITY, segment.above[2]],
            ..segment
        };
        assert!(!wray.outside(p0, p1, p2, &along_kz_only));
    }

    #[test]
    fn degenerate_triangles_are_never_hit() {
        let degenerate = [
            [Vec3::ZERO, Vec3::X, 2.0 * Vec3::X],
            [
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(2.0, 2.0, 0.0),
            ],
            [
                Vec3::ZERO,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.5, 0.5, 0.0),
            ],
            [Vec3::ONE; 3],
            [Vec3::ZERO, Vec3::ZERO, Vec3::Y],
        ];
        let mut rng = Rng::new(4);
        for tri in degenerate {
            for _ in 0..1000 {
                let origin = rng.point(-3.0, 3.0);
                let on_triangle = tri[0]
                    .lerp(tri[1], rng.unit_f32())
                    .lerp(tri[2], rng.unit_f32());
                for ray in [
                    Ray::new(origin, on_triangle - origin),
                    Ray::new(origin, Vec3::NEG_Z),
                    Ray::new(origin, tri[0] - origin),
                ] {
                    assert_eq!(hit(ray, tri), None, "{ray:?} hits {tri:?}");
                }
            }
        }
    }

    #[test]
    fn nan_and_zero_inputs_give_no_hit() {
        let nan = f32::NAN;
        let ok = Ray::new(Vec3::new(0.25, 0.25, 1.0), Vec3::new(0.0, 0.0, -1.0));
        let bad_rays = [
            Ray {
                origin: Vec3::new(nan, 0.25, 1.0),
                ..ok
            },
            Ray {
                dir: Vec3::new(0.0, nan, -1.0),
                ..ok
            },
            Ray {
                dir: Vec3::ZERO,
                ..ok
            },
            Ray { tnear: nan, ..ok },
            Ray { tfar: nan, ..ok },
            Ray {
                origin: Vec3::new(f32::INFINITY, 0.25, 1.0),
                ..ok
            },
        ];
        for ray in bad_rays {
            assert_eq!(hit(ray, UNIT), None, "{ray:?}");
        }
        for corner in 0..3 {
            let mut tri = UNIT;
            tri[corner].y = nan;
            assert_eq!(hit(ok, tri), None, "NaN in corner {corner}");
        }
    }

    #[test]
    fn geometric_normal_follows_embree() {
        assert_eq!(geometric_normal(Vec3::ZERO, Vec3::X, Vec3::Y), Vec3::Z);
        assert_eq!(
            geometric_normal(Vec3::ZERO, 2.0 * Vec3::Y, 3.0 * Vec3::X),
            Vec3::new(0.0, 0.0, -6.0)
        );
    }
}

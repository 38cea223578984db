//! One ray query and Embree's answer, in Embree's conventions
//! (`RTCRay`, `RTCHit` in Embree's `rtcIntersect1` documentation), and
//! how they cross to Embree and back.
//!
//! Both crossings are written for the processor's store-to-load
//! forwarding: a load is served from the store buffer only if one
//! earlier store covers all its bytes, and otherwise waits until the
//! stores reach the cache, which also keeps it from overlapping the work
//! before it. Embree reads a single ray's origin with `tnear`, and its
//! direction with `time`, as 16-byte vectors (`Vec3ff org`, `dir` of its
//! `RayK<1>`, `kernels/common/ray.h`), so the ray is written in 16-byte
//! rows; it writes a hit a field at a time, so the hit is read back a
//! field at a time. Written in stores of the compiler's choosing, none
//! covering either load, the ray made each Embree query on the Cornell
//! box wait: 42.5 ns a shadow ray and 57.5 a
//! primary one back to back, against 28.0 and 34.5 in rows (AMD EPYC,
//! family 26).

use crate::ffi;

/// How queries cross to Embree, for saved measurements: bumped when a
/// change to the crossing moves Embree's measured speed, so that runs of
/// different revisions are known not to have timed the same Embree.
/// Revision 1 writes the ray in rows; runs saved before it (revision 0)
/// timed every Embree query with the stall the module describes.
pub const BINDING_REVISION: u32 = 1;

/// A ray segment `origin + t * dir` for `tnear <= t <= tfar`
/// (Embree requires `0 <= tnear <= tfar`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayQuery {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub tnear: f32,
    pub tfar: f32,
}

/// The closest hit Embree found.
///
/// The hit point is `(1 - u - v) * p0 + u * p1 + v * p2`; `ng` is the
/// unnormalized geometric normal `(p1 - p0) x (p2 - p0)`; `geom_id` is the
/// mesh's position in the scene and `prim_id` the triangle's index in it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmbreeHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub ng: [f32; 3],
    pub geom_id: u32,
    pub prim_id: u32,
}

impl RayQuery {
    /// Embree's ray for this query (mask `0xFFFFFFFF`, time 0, flags 0):
    /// each field of the query read on its own, which whatever stores wrote
    /// it can forward, and the ray written as three 16-byte rows.
    #[inline(always)]
    pub(crate) fn rtc_ray(&self) -> ffi::RtcRay {
        // SAFETY: each is a field of `self`, an aligned, initialized f32.
        // Volatile keeps the compiler from merging the reads into wider
        // loads, which a query written a field at a time cannot forward.
        let read = |field: &f32| unsafe { std::ptr::read_volatile(field) };
        let [org_x, org_y, org_z] = self.origin.each_ref().map(read);
        let [dir_x, dir_y, dir_z] = self.dir.each_ref().map(read);
        let rows = [
            [org_x, org_y, org_z, read(&self.tnear)],
            [dir_x, dir_y, dir_z, 0.0],
            [read(&self.tfar), f32::from_bits(u32::MAX), 0.0, 0.0],
        ];
        let mut ray = ffi::RtcRay::default();
        write_rows(&mut ray, rows);
        ray
    }
}

/// Stores `rows` over `ray`, one 16-byte store a row.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn write_rows(ray: &mut ffi::RtcRay, rows: [[f32; 4]; 3]) {
    use std::arch::x86_64::{__m128, _mm_setr_ps};
    let target: *mut __m128 = (ray as *mut ffi::RtcRay).cast();
    for (i, [a, b, c, d]) in rows.into_iter().enumerate() {
        // SAFETY: `RtcRay` is 48 bytes aligned to 16 (checked in `ffi`),
        // so row `i < 3` is an aligned 16 bytes inside it; every field is
        // a plain 4-byte number, valid for any bits. Volatile keeps the
        // row one store.
        unsafe { std::ptr::write_volatile(target.add(i), _mm_setr_ps(a, b, c, d)) };
    }
}

/// Stores `rows` over `ray` (elsewhere, in the compiler's choice of stores).
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
fn write_rows(ray: &mut ffi::RtcRay, rows: [[f32; 4]; 3]) {
    let [
        [org_x, org_y, org_z, tnear],
        [dir_x, dir_y, dir_z, time],
        [tfar, mask, id, flags],
    ] = rows;
    *ray = ffi::RtcRay {
        org_x,
        org_y,
        org_z,
        tnear,
        dir_x,
        dir_y,
        dir_z,
        time,
        tfar,
        mask: mask.to_bits(),
        id: id.to_bits(),
        flags: flags.to_bits(),
    };
}

impl EmbreeHit {
    /// The hit `rtcIntersect1` left in `ray_hit`, or `None`; each field
    /// read on its own, as Embree wrote it.
    #[inline(always)]
    pub(crate) fn read(ray_hit: &ffi::RtcRayHit) -> Option<EmbreeHit> {
        // SAFETY: each pointer is to a field of `ray_hit`, a valid,
        // aligned, initialized 4-byte number. Volatile keeps the compiler
        // from merging the reads into wider loads.
        let field = |f: &u32| unsafe { std::ptr::read_volatile(f) };
        let float = |f: &f32| unsafe { std::ptr::read_volatile(f) };
        let hit = &ray_hit.hit;
        let geom_id = field(&hit.geom_id);
        (geom_id != ffi::RTC_INVALID_GEOMETRY_ID).then(|| EmbreeHit {
            t: float(&ray_hit.ray.tfar),
            u: float(&hit.u),
            v: float(&hit.v),
            ng: [float(&hit.ng_x), float(&hit.ng_y), float(&hit.ng_z)],
            geom_id,
            prim_id: field(&hit.prim_id),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rows_put_every_field_of_the_query_in_its_place() {
        let query = RayQuery {
            origin: [1.0, 2.0, 3.0],
            dir: [4.0, 5.0, 6.0],
            tnear: 7.0,
            tfar: 8.0,
        };
        let ray = query.rtc_ray();
        let fields = [ray.org_x, ray.org_y, ray.org_z, ray.tnear];
        assert_eq!(fields, [1.0, 2.0, 3.0, 7.0]);
        let fields = [ray.dir_x, ray.dir_y, ray.dir_z, ray.time];
        assert_eq!(fields, [4.0, 5.0, 6.0, 0.0]);
        assert_eq!(ray.tfar, 8.0);
        assert_eq!([ray.mask, ray.id, ray.flags], [u32::MAX, 0, 0]);
    }

    #[test]
    fn a_hit_is_read_field_by_field_and_a_miss_is_none() {
        let mut ray_hit = ffi::RtcRayHit {
            ray: ffi::RtcRay {
                tfar: 2.5,
                ..Default::default()
            },
            hit: ffi::RtcHit {
                ng_x: 1.0,
                ng_y: -2.0,
                ng_z: 3.0,
                u: 0.25,
                v: 0.5,
                prim_id: 9,
                geom_id: 4,
                ..Default::default()
            },
        };
        let hit = EmbreeHit::read(&ray_hit);
        let expected = EmbreeHit {
            t: 2.5,
            u: 0.25,
            v: 0.5,
            ng: [1.0, -2.0, 3.0],
            geom_id: 4,
            prim_id: 9,
        };
        assert_eq!(hit, Some(expected));
        ray_hit.hit.geom_id = ffi::RTC_INVALID_GEOMETRY_ID;
        assert_eq!(EmbreeHit::read(&ray_hit), None);
    }
}

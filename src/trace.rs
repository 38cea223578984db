//! The two questions every backend answers.
//!
//! Our BVHs and Embree both implement [`Intersector`]; the renderer, the
//! agreement check and the benchmarks are generic over it, so any render can
//! run on either backend, or on both at once through `check::Checked`.

use crate::geometry::{Hit, Ray};

pub trait Intersector: Sync {
    /// The closest hit with `ray.tnear <= t <= ray.tfar`, if any
    /// (Embree: `rtcIntersect1`).
    fn intersect(&self, ray: &Ray) -> Option<Hit>;

    /// The same answer as [`Intersector::intersect`], for a ray that does
    /// not follow its neighbours (a diffuse or glossy bounce): the caller's
    /// hint, as Embree's `RTC_RAY_QUERY_FLAG_INCOHERENT`, lets a backend
    /// search it another way. Embree's single-ray queries take that flag by
    /// default, and every backend but ours answers as `intersect`.
    fn intersect_incoherent(&self, ray: &Ray) -> Option<Hit> {
        self.intersect(ray)
    }

    /// Whether anything is hit in `[ray.tnear, ray.tfar]` (Embree: `rtcOccluded1`).
    fn occluded(&self, ray: &Ray) -> bool;
}

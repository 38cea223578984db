//! One ray query and Embree's answer, in Embree's conventions
//! (`RTCRay`, `RTCHit` in Embree's `rtcIntersect1` documentation).

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

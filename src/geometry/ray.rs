//! Rays and hits, in Embree's conventions (Embree 4 API, `RTCRay` / `RTCHit`).

use glam::Vec3;

/// A ray segment: points `origin + t * dir` for `tnear <= t <= tfar`.
///
/// `dir` need not be normalized; `t` is measured in units of `dir`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    pub dir: Vec3,
    pub tnear: f32,
    pub tfar: f32,
}

impl Ray {
    /// A ray from `origin` along `dir` over `[0, ∞)`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::segment(origin, dir, 0.0, f32::INFINITY)
    }

    /// A ray restricted to `[tnear, tfar]`.
    pub fn segment(origin: Vec3, dir: Vec3, tnear: f32, tfar: f32) -> Self {
        Self {
            origin,
            dir,
            tnear,
            tfar,
        }
    }

    /// Whether the ray can hit anything: finite origin and direction, a
    /// nonzero direction and an interval `tnear <= tfar` without NaN.
    #[inline(always)]
    pub fn is_traceable(&self) -> bool {
        // `v·0` is 0 for finite components and NaN otherwise: one sum to
        // compare instead of six tests, each a branch.
        let zeros = self.origin * 0.0 + self.dir * 0.0;
        zeros.x + zeros.y + zeros.z == 0.0 && self.dir != Vec3::ZERO && self.tnear <= self.tfar
    }

    /// The eight f32 inputs: origin xyz, direction xyz, `tnear`, `tfar`.
    pub fn inputs(&self) -> [f32; 8] {
        let (o, d) = (self.origin, self.dir);
        [o.x, o.y, o.z, d.x, d.y, d.z, self.tnear, self.tfar]
    }

    /// The ray with these [`Ray::inputs`].
    pub fn from_inputs(v: [f32; 8]) -> Self {
        Self::segment(
            Vec3::new(v[0], v[1], v[2]),
            Vec3::new(v[3], v[4], v[5]),
            v[6],
            v[7],
        )
    }

    /// The point at parameter `t`.
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + t * self.dir
    }
}

/// A closest hit.
///
/// `u` weights the triangle's second vertex and `v` its third, so the hit
/// point is `(1-u-v)·p0 + u·p1 + v·p2`; `ng` is the unnormalized geometric
/// normal `(p1-p0)×(p2-p0)`; `prim` indexes the mesh's triangle list. These
/// are Embree's conventions, so both backends' hits compare field by field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
    pub prim: u32,
    pub ng: Vec3,
}

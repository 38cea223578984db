//! What the renderer and the check need to know about a hit point.

use crate::geometry::offset::offset_ray_origin;
use crate::geometry::{Hit, Ray, TriangleMesh};
use glam::Vec3;

/// A hit resolved against the mesh it came from.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    /// The hit point from the barycentrics, `(1-u-v)·p0 + u·p1 + v·p2`:
    /// more accurate than `origin + t·dir` far from the ray's origin.
    pub position: Vec3,
    /// Unit shading normal, facing the incoming ray: the geometric normal,
    /// or the interpolated one where the renderer sets it.
    pub normal: Vec3,
    /// Unit geometric normal, turned to face the incoming ray: the side
    /// secondary rays are offset to.
    pub geometric_normal: Vec3,
    /// Unit direction back towards the ray's origin.
    pub to_viewer: Vec3,
    pub material: u32,
    pub prim: u32,
    /// The hit's barycentrics (Embree's u, v).
    pub u: f32,
    pub v: f32,
}

impl SurfacePoint {
    pub fn new(mesh: &TriangleMesh, ray: &Ray, hit: &Hit) -> Self {
        let [p0, p1, p2] = mesh.triangle(hit.prim as usize);
        let position = (1.0 - hit.u - hit.v) * p0 + hit.u * p1 + hit.v * p2;
        let ng = hit.ng.normalize_or_zero();
        let normal = if ng.dot(ray.dir) > 0.0 { -ng } else { ng };
        let material = mesh.materials[hit.prim as usize];
        Self {
            position,
            normal,
            geometric_normal: normal,
            to_viewer: -ray.dir.normalize_or_zero(),
            material,
            prim: hit.prim,
            u: hit.u,
            v: hit.v,
        }
    }

    /// The origin for a ray leaving on the viewer's side of the surface.
    pub fn spawn_origin(&self) -> Vec3 {
        offset_ray_origin(self.position, self.geometric_normal)
    }

    /// A shadow ray towards `target` that stops just short of it, so a light
    /// placed on a surface is not shadowed by that surface.
    pub fn shadow_ray(&self, target: Vec3) -> Ray {
        let origin = self.spawn_origin();
        Ray::segment(origin, target - origin, 0.0, SHADOW_RAY_END)
    }

    /// The perfect mirror reflection of the incoming direction about the
    /// shading normal (unit length).
    pub fn mirror_direction(&self) -> Vec3 {
        let incoming = -self.to_viewer;
        incoming - 2.0 * incoming.dot(self.normal) * self.normal
    }

    /// The perfect mirror reflection ray.
    pub fn reflection_ray(&self) -> Ray {
        Ray::new(self.spawn_origin(), self.mirror_direction())
    }
}

/// Shadow rays span `[0, SHADOW_RAY_END]` of the vector to the light.
pub const SHADOW_RAY_END: f32 = 1.0 - 1.0 / 4096.0;

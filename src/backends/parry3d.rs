//! parry3d 0.31 as a [`Backend`]: a `TriMesh` (the shape Rapier and
//! Bevy's physics cast rays against), built with no flags, so its
//! triangles are ours in our order, over the binned BVH it builds itself.
//!
//! Conventions, as parry3d 0.31.1's source has them, and the conversions:
//!
//! - **t range**: the crate takes a ray `origin + t·dir` and a
//!   `max_time_of_impact`, no `tnear`. *Conversion*: the adapter casts from
//!   `origin + tnear·dir` with `tfar - tnear` and adds `tnear` back to the
//!   distance found; both steps round in f32, and are exact when
//!   `tnear = 0`. A `tnear` of `±∞` makes that origin non-finite, and the
//!   ray misses. The triangle test accepts `t <= max`, but the BVH search
//!   keeps a hit only when it is *below* the best so far, which starts at
//!   `max`: a hit exactly at `tfar` is not returned and, of hits at the
//!   same `t`, the first found is kept. A ray starting on a triangle's
//!   plane and leaving it towards the front hits it at `t = 0` (towards
//!   the back: see below).
//! - **Triangle test**: no epsilon. Both faces; a direction exactly
//!   parallel to the plane misses; edges and corners are inside (the
//!   barycentric tests are `>= 0`).
//! - **Closest hit**: `TriMesh::cast_local_ray_and_get_normal` (its BVH
//!   search with the scalar ray/box test); the hit's `subshape` is our
//!   triangle index.
//! - **Any hit**: `TriMesh::intersects_local_ray`, the crate's yes/no
//!   query, which runs its closest-hit search over its SIMD ray/box test
//!   (`cast_inv_ray_simd`) rather than stopping at the first hit.
//! - **u, v**: not given by a `TriMesh` ray cast. [`Hit::u`] and
//!   [`Hit::v`] are zero and [`Backend::answers`] says so.
//! - **Normal**: parry's is `(p1-p0)×(p2-p0)` scaled to unit length, and
//!   negated for a back hit (`FeatureId::Face(1)`) at `t > 0`.
//!   *Conversion*: the adapter negates those back, so the normal has
//!   Embree's direction; its length stays 1 (Embree's is twice the
//!   triangle's area).
//! - **Origin on the plane**: a ray that starts on a triangle's plane and
//!   leaves it towards the back is tested with the front side's
//!   barycentric signs: it misses the triangle and hits, at `t = 0`, the
//!   triangle's point reflection through its first corner (with
//!   `Face(1)` and the front's normal, which the adapter leaves as is).
//!
//! Bytes count the crate's BVH (`Bvh::total_memory_size`) and the mesh's
//! vertices and indices. The build time is the wall time from our mesh to
//! a ready tracer. A mesh without triangles is an error: parry3d cannot
//! build a `TriMesh` from one.

use super::third_party::Crate;
use super::{Answers, Backend, BackendName, Kind, Label};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use glam::Vec3;
use parry3d::math::Vector;
use parry3d::query::{Ray as ParryRay, RayCast};
use parry3d::shape::{FeatureId, TriMesh};
use std::time::{Duration, Instant};

const CRATE: Crate = Crate {
    label: Label {
        name: "parry3d",
        aliases: &[],
        about: "parry3d's TriMesh ray casts (Rapier's and Bevy's physics)",
    },
    build: |mesh| Ok(Box::new(Parry3dBackend::build(mesh)?)),
};

pub(super) const KINDS: &[&dyn Kind] = &[&CRATE];

/// `parry3d`.
pub const PARRY3D: BackendName = BackendName::of(&CRATE);

/// A parry3d `TriMesh` over one mesh.
pub struct Parry3dBackend {
    mesh: TriMesh,
    build_time: Duration,
}

impl Parry3dBackend {
    /// Builds the crate's `TriMesh` (and so its BVH) over `mesh`.
    pub fn build(mesh: &TriangleMesh) -> anyhow::Result<Self> {
        let start = Instant::now();
        let vertices = mesh
            .positions
            .iter()
            .map(|p| Vector::new(p.x, p.y, p.z))
            .collect();
        let mesh = TriMesh::new(vertices, mesh.indices.clone())
            .map_err(|e| anyhow::anyhow!("parry3d cannot build this mesh: {e}"))?;
        Ok(Self {
            mesh,
            build_time: start.elapsed(),
        })
    }

    /// Our ray as the crate's, starting at `tnear`, and the longest
    /// distance it may travel from there.
    fn ray(ray: &Ray) -> (ParryRay, f32) {
        let start = ray.at(ray.tnear);
        let d = ray.dir;
        (
            ParryRay::new(
                Vector::new(start.x, start.y, start.z),
                Vector::new(d.x, d.y, d.z),
            ),
            ray.tfar - ray.tnear,
        )
    }
}

impl Intersector for Parry3dBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let (query, max) = Self::ray(ray);
        let hit = self
            .mesh
            .cast_local_ray_and_get_normal(&query, max, false)?;
        let toi = hit.time_of_impact;
        let back = hit.feature == FeatureId::Face(1) && toi > 0.0;
        let normal = if back { -hit.normal } else { hit.normal };
        Some(Hit {
            t: ray.tnear + toi,
            u: 0.0,
            v: 0.0,
            prim: hit.subshape,
            ng: Vec3::new(normal.x, normal.y, normal.z),
        })
    }

    fn occluded(&self, ray: &Ray) -> bool {
        let (query, max) = Self::ray(ray);
        self.mesh.intersects_local_ray(&query, max)
    }
}

impl Backend for Parry3dBackend {
    fn name(&self) -> String {
        PARRY3D.to_string()
    }
    fn answers(&self) -> Answers {
        Answers {
            uv: false,
            normal: true,
        }
    }
    fn build_time(&self) -> Duration {
        self.build_time
    }
    fn bytes(&self) -> Option<usize> {
        Some(
            self.mesh.bvh().total_memory_size()
                + std::mem::size_of_val(self.mesh.vertices())
                + std::mem::size_of_val(self.mesh.indices()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{Answer, Judgement, Referee};

    #[test]
    fn back_face_normals_are_turned_to_embree_winding() {
        let mesh = TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let backend = Parry3dBackend::build(&mesh).unwrap();
        let up = Ray::new(Vec3::new(0.25, 0.5, -1.0), Vec3::Z);
        let (query, max) = Parry3dBackend::ray(&up);
        let raw = backend
            .mesh
            .cast_local_ray_and_get_normal(&query, max, false)
            .unwrap();
        assert_eq!(raw.feature, FeatureId::Face(1));
        assert_eq!(raw.normal, Vector::NEG_Z);
        let hit = backend.intersect(&up).unwrap();
        assert_eq!((hit.t, hit.prim, hit.ng), (1.0, 0, Vec3::Z));
    }

    #[test]
    fn no_u_v_are_given() {
        let mesh = TriangleMesh::soup(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let backend = Parry3dBackend::build(&mesh).unwrap();
        assert!(!backend.answers().uv);
        let hit = backend
            .intersect(&Ray::new(Vec3::new(0.25, 0.5, 1.0), Vec3::NEG_Z))
            .unwrap();
        assert_eq!((hit.u, hit.v), (0.0, 0.0));
    }

    #[test]
    fn a_ray_leaving_the_plane_to_the_back_hits_the_mirror_image() {
        // A sliver whose first corner lies inside its own box; its normal
        // is +z. The origin is on its plane, outside it, inside its box,
        // at the point reflection through the first corner of a point
        // inside it.
        let mesh = TriangleMesh::soup(&[[
            Vec3::new(0.5, 0.6, 0.0),
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ]]);
        let backend = Parry3dBackend::build(&mesh).unwrap();
        let ray = Ray::new(Vec3::new(0.5, 0.62, 0.0), Vec3::Z);
        let hit = backend.intersect(&ray).unwrap();
        assert_eq!((hit.t, hit.prim), (0.0, 0));
        assert!(backend.occluded(&ray));
        let referee = Referee::new(&mesh);
        assert_eq!(
            referee.judge(&ray, Answer::Closest(Some(hit))),
            Judgement::Wrong
        );
        assert_eq!(referee.judge(&ray, Answer::Closest(None)), Judgement::Right);
        // Towards the front the same origin misses, as it should.
        assert_eq!(
            backend.intersect(&Ray {
                dir: Vec3::NEG_Z,
                ..ray
            }),
            None
        );
    }
}

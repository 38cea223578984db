//! The `bvh` crate 0.13 (svenstaro's) as a [`Backend`]: its binary SAH
//! BVH built in parallel (`Bvh::build_par`), traversed with `Bvh::traverse`
//! as its README does, every candidate tested with the crate's own
//! Möller–Trumbore test (`Ray::intersects_triangle`).
//!
//! The crate has a ray/box query, not a ray tracer: it returns every
//! triangle whose box the ray meets, and the adapter keeps the nearest hit.
//! Conventions, as bvh 0.13.0's source has them, and the conversions:
//!
//! - **t range**: the crate's ray has no interval, and `Ray::new`
//!   normalizes the direction, so its distances are along the unit
//!   direction. *Conversion*: the adapter divides a distance by the f32
//!   length of our direction to get our `t`, then keeps hits with
//!   `tnear <= t <= tfar`. Of hits at the same `t`, the first the
//!   traversal returns is kept.
//! - **Epsilons**: a hit needs a determinant of at least `f32::EPSILON`
//!   (with the unit direction, so small or grazing triangles are missed)
//!   and a distance above `f32::EPSILON` along the unit direction.
//! - **Back faces**: the crate's test culls them (a determinant below
//!   `f32::EPSILON`). *Conversion*: where the front test misses, the
//!   adapter runs the crate's test again with the corners in the order
//!   (p0, p2, p1), which is the back face seen from the front, so every
//!   triangle answers from both sides as in Embree.
//! - **Inside**: `u`, `v` in `[0, 1]` and `u + v <= 1`, edges included.
//! - **Boxes**: a ray whose slab arithmetic gives a NaN (an axis-parallel
//!   ray in the plane of a box face: `0 × ∞`) misses that box.
//! - **Triangle index**: the adapter's shapes carry our triangle index.
//! - **Any hit**: the same traversal, stopping at the first hit in
//!   `[tnear, tfar]`.
//! - **u, v**: the crate's; its `u` weights the second corner it is given
//!   and `v` the third, so a front hit is in Embree's convention already
//!   and a back hit (corners p0, p2, p1) has them swapped back.
//! - **Normal**: the crate gives none; [`Hit::ng`] is zero and
//!   [`Backend::answers`] says so.
//!
//! Bytes count the crate's nodes and the adapter's triangles. The build
//! time is the wall time from our mesh to a ready tracer.

use super::third_party::Crate;
use super::{Answers, Backend, BackendName, Kind, Label};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use bvh::aabb::{Aabb, Bounded};
use bvh::bounding_hierarchy::{BHShape, BoundingHierarchy};
use bvh::bvh::Bvh;
use bvh::ray::Ray as BvhRay;
use glam::Vec3;
use nalgebra::{Point3, Vector3};
use std::time::{Duration, Instant};

const CRATE: Crate = Crate {
    label: Label {
        name: "bvh",
        aliases: &[],
        about: "svenstaro's bvh crate: binary SAH BVH, Möller–Trumbore",
    },
    build: |mesh| Ok(Box::new(BvhCrateBackend::build(mesh)?)),
};

pub(super) const KINDS: &[&dyn Kind] = &[&CRATE];

/// `bvh`.
pub const BVH_CRATE: BackendName = BackendName::of(&CRATE);

/// One triangle as the crate's BVH stores it.
struct Shape {
    corners: [Point3<f32>; 3],
    /// Our triangle index.
    prim: u32,
    /// Set by the crate's build.
    node_index: usize,
}

impl Bounded<f32, 3> for Shape {
    fn aabb(&self) -> Aabb<f32, 3> {
        let [a, b, c] = &self.corners;
        Aabb::empty().grow(a).grow(b).grow(c)
    }
}

impl BHShape<f32, 3> for Shape {
    fn set_bh_node_index(&mut self, index: usize) {
        self.node_index = index;
    }
    fn bh_node_index(&self) -> usize {
        self.node_index
    }
}

/// A hit in our units: `t`, and `u`, `v` in Embree's convention.
struct Candidate {
    t: f32,
    u: f32,
    v: f32,
    prim: u32,
}

/// svenstaro's `bvh` over one mesh.
pub struct BvhCrateBackend {
    bvh: Bvh<f32, 3>,
    shapes: Vec<Shape>,
    build_time: Duration,
}

impl BvhCrateBackend {
    /// Builds the crate's BVH over `mesh` with `Bvh::build_par`; an error
    /// where the crate's build panics (it does on infinite coordinates).
    pub fn build(mesh: &TriangleMesh) -> anyhow::Result<Self> {
        let start = Instant::now();
        let mut shapes: Vec<Shape> = (0..mesh.triangle_count())
            .map(|prim| Shape {
                corners: mesh.triangle(prim).map(|p| Point3::new(p.x, p.y, p.z)),
                prim: prim as u32,
                node_index: 0,
            })
            .collect();
        let bvh = super::guard::build_or_error("bvh", || Bvh::build_par(&mut shapes))?;
        Ok(Self {
            bvh,
            shapes,
            build_time: start.elapsed(),
        })
    }

    /// The hits in `[tnear, tfar]` of the triangles whose boxes the ray
    /// meets, in the crate's traversal order.
    fn candidates<'a>(&'a self, ray: &'a Ray) -> impl Iterator<Item = Candidate> + 'a {
        let (o, d) = (ray.origin, ray.dir);
        let query = BvhRay::new(Point3::new(o.x, o.y, o.z), Vector3::new(d.x, d.y, d.z));
        let length = d.length();
        self.bvh
            .traverse(&query, &self.shapes)
            .into_iter()
            .filter_map(move |shape| {
                let [a, b, c] = &shape.corners;
                let front = query.intersects_triangle(a, b, c);
                let (distance, u, v) = if front.distance < f32::INFINITY {
                    (front.distance, front.u, front.v)
                } else {
                    let back = query.intersects_triangle(a, c, b);
                    (back.distance, back.v, back.u)
                };
                let t = distance / length;
                (distance < f32::INFINITY && ray.tnear <= t && t <= ray.tfar).then_some(Candidate {
                    t,
                    u,
                    v,
                    prim: shape.prim,
                })
            })
    }
}

impl Intersector for BvhCrateBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let nearest = self
            .candidates(ray)
            .reduce(|best, c| if c.t < best.t { c } else { best })?;
        Some(Hit {
            t: nearest.t,
            u: nearest.u,
            v: nearest.v,
            prim: nearest.prim,
            ng: Vec3::ZERO,
        })
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.candidates(ray).next().is_some()
    }
}

impl Backend for BvhCrateBackend {
    fn name(&self) -> String {
        BVH_CRATE.to_string()
    }
    fn answers(&self) -> Answers {
        Answers {
            uv: true,
            normal: false,
        }
    }
    fn build_time(&self) -> Duration {
        self.build_time
    }
    fn bytes(&self) -> Option<usize> {
        Some(
            std::mem::size_of_val(self.bvh.nodes.as_slice())
                + std::mem::size_of_val(self.shapes.as_slice()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{Answer, Judgement, Referee};

    fn unit_triangle(scale: f32) -> TriangleMesh {
        TriangleMesh::soup(&[[Vec3::ZERO, scale * Vec3::X, scale * Vec3::Y]])
    }

    fn down_onto(x: f32, y: f32, height: f32) -> Ray {
        Ray::new(Vec3::new(x, y, height), Vec3::NEG_Z)
    }

    /// Whether the referee calls a miss on `ray` wrong.
    fn a_miss_is_wrong(mesh: &TriangleMesh, ray: Ray) -> bool {
        Referee::new(mesh).judge(&ray, Answer::Closest(None)) == Judgement::Wrong
    }

    #[test]
    fn back_faces_are_answered_through_the_reversed_winding() {
        let backend = BvhCrateBackend::build(&unit_triangle(1.0)).unwrap();
        let up = Ray::new(Vec3::new(0.25, 0.5, -1.0), Vec3::Z);
        // The crate's own test culls the back face...
        let [a, b, c] = &backend.shapes[0].corners;
        let query = BvhRay::new(Point3::new(0.25, 0.5, -1.0), Vector3::new(0.0, 0.0, 1.0));
        assert_eq!(query.intersects_triangle(a, b, c).distance, f32::INFINITY);
        // ...and with the corners swapped it answers, u and v swapped back.
        let hit = backend.intersect(&up).unwrap();
        assert_eq!((hit.t, hit.u, hit.v, hit.prim), (1.0, 0.25, 0.5, 0));
    }

    #[test]
    fn distances_are_converted_from_the_unit_direction() {
        let backend = BvhCrateBackend::build(&unit_triangle(1.0)).unwrap();
        let long = Ray::new(Vec3::new(0.25, 0.5, 8.0), Vec3::new(0.0, 0.0, -4.0));
        assert_eq!(backend.intersect(&long).unwrap().t, 2.0);
    }

    #[test]
    fn small_triangles_fall_below_the_determinant_epsilon() {
        // Edges of 1e-4 give a determinant of 1e-8 < f32::EPSILON.
        let mesh = unit_triangle(1e-4);
        let backend = BvhCrateBackend::build(&mesh).unwrap();
        let ray = down_onto(0.25e-4, 0.5e-4, 1.0);
        assert_eq!(backend.intersect(&ray), None);
        assert!(!backend.occluded(&ray));
        assert!(a_miss_is_wrong(&mesh, ray));
        // At a scale of 1e-3 the determinant (1e-6) passes.
        assert!(
            BvhCrateBackend::build(&unit_triangle(1e-3))
                .unwrap()
                .occluded(&down_onto(2.5e-4, 5e-4, 1.0))
        );
    }

    #[test]
    fn an_axis_parallel_ray_in_a_box_face_plane_misses_the_box() {
        // Two triangles sharing the edge x = 0; a ray straight down onto
        // that edge has 0 × ∞ = NaN in both boxes' x slab.
        let mesh = TriangleMesh::soup(&[
            [Vec3::new(-1.0, 0.0, 0.0), Vec3::ZERO, Vec3::Y],
            [Vec3::ZERO, Vec3::X, Vec3::Y],
        ]);
        let backend = BvhCrateBackend::build(&mesh).unwrap();
        let on_edge = down_onto(0.0, 0.25, 1.0);
        assert_eq!(backend.intersect(&on_edge), None);
        assert!(a_miss_is_wrong(&mesh, on_edge));
        // Tilted by a little, the same ray hits.
        let tilted = Ray::new(on_edge.origin, Vec3::new(1e-3, 0.0, -1.0));
        assert_eq!(backend.intersect(&tilted).unwrap().prim, 1);
    }

    #[test]
    fn hits_within_the_distance_epsilon_are_dropped() {
        let mesh = unit_triangle(1.0);
        let backend = BvhCrateBackend::build(&mesh).unwrap();
        let near = down_onto(0.25, 0.5, 1e-7);
        assert_eq!(backend.intersect(&near), None);
        assert!(a_miss_is_wrong(&mesh, near));
        assert!(backend.occluded(&down_onto(0.25, 0.5, 1e-6)));
    }
}

//! obvhs 0.4 as a [`Backend`]: its compressed wide BVH8 (CWBVH, Ylitie et
//! al. 2017) built by its PLOC builder (Meister & Bittner 2018), traced on
//! the CPU the way the crate's own examples trace it.
//!
//! The build is `build_cwbvh_from_tris` with the `medium_build` preset
//! (PLOC, reinsertion, no spatial pre-splits, so every triangle is one
//! primitive), then the triangles laid out in the tree's
//! `primitive_indices` order as the crate's CPU triangles (`RtTriangle`).
//! Conventions, as obvhs 0.4.0's source has them:
//!
//! - **t range**: native. The crate's ray carries `tmin` and `tmax`; its
//!   triangle test accepts `tmin <= t <= tmax`, but its traversal keeps a
//!   hit only when `t` is *below* the current `tmax`, so a hit exactly at
//!   `tfar` is not returned and, of hits at the same `t`, the first found
//!   is kept. Its box test ignores `tmin` and starts every box interval at
//!   `1e-4` (the constant `EPSILON` of its node test), so a hit whose leaf
//!   box the ray leaves before `t = 1e-4` is not found.
//!   The start is in the ray's parameter, so with a long direction (a
//!   shadow ray to a light) it covers a long way.
//! - **Directions**: for the box test, a direction component with
//!   `|d| <= f32::EPSILON` gets the inverse `±1/f32::EPSILON` (the crate's
//!   `safe_inverse`, by the sign bit) instead of `±∞`. The box test picks
//!   each slab's near and far planes by `d < 0`, which is false for
//!   `-0.0` while its inverse is negative: a ray with a `-0.0` component
//!   misses every box that is not flat along that axis.
//! - **Triangle test** (`RtTriangle::intersect`): Möller–Trumbore without
//!   an epsilon, both faces. A hit needs a non-zero determinant and `u`,
//!   `v`, `1-u-v` with clear sign bits, so an edge value of `-0.0` is
//!   outside. From behind (a negative determinant) an exact zero comes out
//!   as `-0.0`: a ray from behind through a shared vertex or along a
//!   shared edge can miss every triangle there.
//! - **Triangle index**: the hit's `primitive_id` indexes the tree's
//!   `primitive_indices`, which holds our triangle index.
//! - **Any hit**: native (`ray_traverse_miss`: the first hit below `tfar`
//!   ends the traversal).
//! - **u, v**: the crate's `RtTriangle::compute_barycentric` for the hit
//!   triangle, the same arithmetic as its hit test; its `u` weights the
//!   second vertex and `v` the third, Embree's convention already.
//! - **Normal**: the crate's stored `ng` is `(p0-p1)×(p2-p0)`; negated, it
//!   is Embree's unnormalized `(p1-p0)×(p2-p0)` (negation is exact).
//!
//! Bytes count the nodes, `primitive_indices` and the triangles the
//! traversal reads. The build time is the wall time from our mesh to a
//! ready tracer (the crate's triangles made, the tree built, the triangles
//! laid out).

use super::third_party::Crate;
use super::{Answers, Backend, BackendName, Kind, Label};
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::trace::Intersector;
use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::{Ray as ObvhsRay, RayHit};
use obvhs::rt_triangle::RtTriangle;
use obvhs::triangle::Triangle;
use std::time::{Duration, Instant};

const CRATE: Crate = Crate {
    label: Label {
        name: "obvhs",
        aliases: &[],
        about: "the obvhs crate: CWBVH (Ylitie et al. 2017) from its PLOC builder",
    },
    build: |mesh| Ok(Box::new(ObvhsBackend::build(mesh)?)),
};

pub(super) const KINDS: &[&dyn Kind] = &[&CRATE];

/// `obvhs`.
pub const OBVHS: BackendName = BackendName::of(&CRATE);

/// An obvhs CWBVH over one mesh.
pub struct ObvhsBackend {
    bvh: CwBvh,
    /// The triangles in `bvh.primitive_indices` order.
    triangles: Vec<RtTriangle>,
    build_time: Duration,
}

impl ObvhsBackend {
    /// Builds the CWBVH over `mesh` with the crate's `medium_build` preset;
    /// an error where the crate's build panics (it does on infinite
    /// coordinates, on a NaN in some corners and on coordinates near
    /// `f32::MAX`).
    pub fn build(mesh: &TriangleMesh) -> anyhow::Result<Self> {
        let start = Instant::now();
        let input: Vec<Triangle> = (0..mesh.triangle_count())
            .map(|prim| {
                let [v0, v1, v2] = mesh.triangle(prim).map(Vec3A::from);
                Triangle { v0, v1, v2 }
            })
            .collect();
        let bvh = super::guard::build_or_error("obvhs", || {
            build_cwbvh_from_tris(
                &input,
                BvhBuildParams::medium_build(),
                &mut Duration::default(),
            )
        })?;
        let triangles = bvh
            .primitive_indices
            .iter()
            .map(|&prim| RtTriangle::from(&input[prim as usize]))
            .collect();
        Ok(Self {
            bvh,
            triangles,
            build_time: start.elapsed(),
        })
    }

    /// Our ray as the crate's, interval and all.
    fn ray(ray: &Ray) -> ObvhsRay {
        ObvhsRay::new(ray.origin.into(), ray.dir.into(), ray.tnear, ray.tfar)
    }
}

impl Intersector for ObvhsBackend {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let query = Self::ray(ray);
        let mut hit = RayHit::none();
        let found = self
            .bvh
            .ray_traverse(query, &mut hit, |r, id| self.triangles[id].intersect(r));
        if !found {
            return None;
        }
        let slot = hit.primitive_id as usize;
        let triangle = &self.triangles[slot];
        let uv = triangle.compute_barycentric(&query);
        Some(Hit {
            t: hit.t,
            u: uv.x,
            v: uv.y,
            prim: self.bvh.primitive_indices[slot],
            ng: Vec3::from(-triangle.ng),
        })
    }

    fn occluded(&self, ray: &Ray) -> bool {
        !self
            .bvh
            .ray_traverse_miss(Self::ray(ray), |r, id| self.triangles[id].intersect(r))
    }
}

impl Backend for ObvhsBackend {
    fn name(&self) -> String {
        OBVHS.to_string()
    }
    fn answers(&self) -> Answers {
        Answers::ALL
    }
    fn build_time(&self) -> Duration {
        self.build_time
    }
    fn bytes(&self) -> Option<usize> {
        Some(
            std::mem::size_of_val(self.bvh.nodes.as_slice())
                + std::mem::size_of_val(self.bvh.primitive_indices.as_slice())
                + std::mem::size_of_val(self.triangles.as_slice()),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::{Answer, Judgement, Referee};

    /// The unit triangle in z = 0 and a second triangle beside it in the
    /// same plane.
    fn flat_pair() -> TriangleMesh {
        TriangleMesh::soup(&[
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [
                Vec3::new(5.0, 0.0, 0.0),
                Vec3::new(6.0, 0.0, 0.0),
                Vec3::new(5.0, 1.0, 0.0),
            ],
        ])
    }

    #[test]
    fn a_hit_nearer_than_the_box_epsilon_is_lost() {
        let mesh = flat_pair();
        let backend = ObvhsBackend::build(&mesh).unwrap();
        let exact = Hit {
            t: 0.0,
            u: 0.25,
            v: 0.5,
            prim: 0,
            ng: Vec3::Z,
        };
        for (height, found) in [(2e-4f32, true), (5e-5, false)] {
            let ray = Ray::new(Vec3::new(0.25, 0.5, height), Vec3::NEG_Z);
            let hit = backend.intersect(&ray);
            assert_eq!(hit.is_some(), found, "{ray:?}");
            assert_eq!(backend.occluded(&ray), found, "{ray:?}");
            if !found {
                // The triangle test alone finds it: the box test dropped it.
                let triangle = RtTriangle::from(&Triangle {
                    v0: Vec3A::ZERO,
                    v1: Vec3A::X,
                    v2: Vec3A::Y,
                });
                assert_eq!(triangle.intersect(&ObvhsBackend::ray(&ray)), height);
                let referee = Referee::new(&mesh);
                assert_eq!(referee.judge(&ray, Answer::Closest(hit)), Judgement::Wrong);
                let right = Some(Hit { t: height, ..exact });
                assert_eq!(
                    referee.judge(&ray, Answer::Closest(right)),
                    Judgement::Right
                );
            }
        }
    }

    /// Whether the referee calls `claim` wrong on `ray` where our hit on
    /// `mesh` is `right`.
    fn judged_wrong(mesh: &TriangleMesh, ray: Ray, claim: Option<Hit>, right: Hit) -> bool {
        let referee = Referee::new(mesh);
        referee
            .judge(&ray, Answer::Closest(Some(right)))
            .is_admissible()
            && referee.judge(&ray, Answer::Closest(claim)) == Judgement::Wrong
    }

    #[test]
    fn a_ray_through_a_shared_vertex_from_behind_misses_every_triangle() {
        // Four triangles around the origin, all facing +z.
        let mesh = TriangleMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::NEG_X, Vec3::NEG_Y],
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
        );
        let backend = ObvhsBackend::build(&mesh).unwrap();
        let from_front = Ray::new(Vec3::Z, Vec3::NEG_Z);
        assert_eq!(backend.intersect(&from_front).unwrap().t, 1.0);
        // From behind the determinant is negative, so the exact zero
        // barycentrics come out as -0.0, which the sign-bit test rejects.
        let from_behind = Ray::new(Vec3::NEG_Z, Vec3::Z);
        let miss = backend.intersect(&from_behind);
        assert_eq!(miss, None);
        assert!(!backend.occluded(&from_behind));
        let right = Hit {
            t: 1.0,
            u: 0.0,
            v: 0.0,
            prim: 0,
            ng: Vec3::Z,
        };
        assert!(judged_wrong(&mesh, from_behind, miss, right));
    }

    #[test]
    fn a_negative_zero_direction_component_misses_the_boxes() {
        let mesh = flat_pair();
        let backend = ObvhsBackend::build(&mesh).unwrap();
        let down = |dx: f32| Ray::new(Vec3::new(0.25, 0.5, 1.0), Vec3::new(dx, 0.0, -1.0));
        assert_eq!(backend.intersect(&down(0.0)).unwrap().t, 1.0);
        let ray = down(-0.0);
        // The triangle test alone finds it; the traversal does not.
        assert_eq!(
            backend.triangles[0].intersect(&ObvhsBackend::ray(&ray)),
            1.0
        );
        let miss = backend.intersect(&ray);
        assert_eq!(miss, None);
        assert!(!backend.occluded(&ray));
        let right = Hit {
            t: 1.0,
            u: 0.25,
            v: 0.5,
            prim: 0,
            ng: Vec3::Z,
        };
        assert!(judged_wrong(&mesh, ray, miss, right));
    }

    #[test]
    fn a_hit_exactly_at_tfar_is_not_returned() {
        let backend = ObvhsBackend::build(&flat_pair()).unwrap();
        let down = |tfar: f32| Ray::segment(Vec3::new(0.25, 0.5, 1.0), Vec3::NEG_Z, 0.0, tfar);
        assert_eq!(backend.intersect(&down(1.0)), None);
        assert!(!backend.occluded(&down(1.0)));
        assert_eq!(backend.intersect(&down(1f32.next_up())).unwrap().t, 1.0);
        assert!(backend.occluded(&down(1f32.next_up())));
    }

    #[test]
    fn the_tree_is_the_same_on_any_thread_count() {
        let mut rng = crate::random::Rng::new(3);
        let triangles: Vec<[Vec3; 3]> = (0..50_000)
            .map(|_| {
                let c = rng.point(-1.0, 1.0);
                [(); 3].map(|_| c + rng.point(-0.02, 0.02))
            })
            .collect();
        let mesh = TriangleMesh::soup(&triangles);
        let on = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let backend = pool.install(|| ObvhsBackend::build(&mesh)).unwrap();
            (backend.bvh, backend.triangles)
        };
        let one = on(1);
        assert_eq!(one.1.len(), mesh.triangle_count());
        assert!(
            one == on(2) && one == on(4),
            "the build depends on the thread count"
        );
    }
}

//! The third-party crates behind `Backend` (obvhs, bvh, parry3d): their
//! hits follow Embree's conventions as far as each adapter says it gives
//! them, they agree with our BVH wherever the exact referee is sure, and a
//! wrong answer planted in one of them is caught, on exactly that ray.

use glam::Vec3;
use raycheck::backends::parry3d::PARRY3D;
use raycheck::backends::{Answers, Backend, BackendName, Group};
use raycheck::bvh::wide::WideBvh;
use raycheck::check::{CheckLog, Checked, Judgement};
use raycheck::geometry::{Hit, Ray, TriangleMesh};
use raycheck::random::Rng;
use raycheck::results::Verdicts;
use raycheck::scene;
use raycheck::stability::shapes::{Placement, grid, icosphere};
use raycheck::trace::Intersector;
use rayon::prelude::*;

/// The crates, as the registry groups them.
fn crates() -> Vec<String> {
    BackendName::in_group(Group::Crate)
        .iter()
        .map(|name| name.to_string())
        .collect()
}

fn build(name: &str, mesh: &TriangleMesh) -> Box<dyn Backend> {
    let name: BackendName = name.parse().unwrap();
    name.build(mesh, crate::support::workers(Some(1)).build_context())
        .unwrap()
}

/// Where the unit triangle sits in [`placed_unit_triangle`].
const UNIT_PRIM: u32 = 41;

/// 64 small triangles well above z = 0, with triangle [`UNIT_PRIM`]
/// replaced by the unit triangle (0,0,0), (1,0,0), (0,1,0): a builder that
/// reorders triangles must still report our index.
fn placed_unit_triangle() -> TriangleMesh {
    let mut rng = Rng::new(9);
    let mut triangles: Vec<[Vec3; 3]> = (0..64)
        .map(|_| {
            let c = rng.point(-2.0, 2.0) + 6.0 * Vec3::Z;
            [c, c + 0.3 * Vec3::X, c + 0.3 * Vec3::Y]
        })
        .collect();
    triangles[UNIT_PRIM as usize] = [Vec3::ZERO, Vec3::X, Vec3::Y];
    TriangleMesh::soup(&triangles)
}

/// Down onto (0.25, 0.5) of the unit triangle from z = 1: its front.
fn from_above() -> Ray {
    Ray::new(Vec3::new(0.25, 0.5, 1.0), Vec3::NEG_Z)
}

/// Up onto (0.25, 0.5) from z = -1: its back.
fn from_below() -> Ray {
    Ray::new(Vec3::new(0.25, 0.5, -1.0), Vec3::Z)
}

#[test]
fn hits_follow_embree_conventions_from_both_sides() {
    let mesh = placed_unit_triangle();
    for name in &crates() {
        let backend = build(name, &mesh);
        let answers = backend.answers();
        for ray in [from_above(), from_below()] {
            let hit = backend
                .intersect(&ray)
                .unwrap_or_else(|| panic!("{name}: {ray:?}"));
            assert_eq!((hit.t, hit.prim), (1.0, UNIT_PRIM), "{name}: {ray:?}");
            if answers.uv {
                // u weights the second corner (1,0,0), v the third (0,1,0).
                assert_eq!((hit.u, hit.v), (0.25, 0.5), "{name}: {ray:?}");
            }
            if answers.normal {
                // The direction of (p1-p0)×(p2-p0), whichever side is hit.
                assert_eq!(hit.ng.normalize(), Vec3::Z, "{name}: {ray:?}");
            }
            assert!(backend.occluded(&ray), "{name}: {ray:?}");
        }
    }
}

#[test]
fn t_intervals_are_honoured() {
    let mesh = placed_unit_triangle();
    let segment = |tnear, tfar| Ray {
        tnear,
        tfar,
        ..from_above()
    };
    for name in &crates() {
        let backend = build(name, &mesh);
        for (ray, hits) in [
            (segment(0.5, 1.5), true),
            (segment(0.0, 0.5), false),
            (segment(1.5, f32::INFINITY), false),
        ] {
            let hit = backend.intersect(&ray);
            assert_eq!(hit.is_some(), hits, "{name}: {ray:?}");
            if let Some(hit) = hit {
                assert_eq!((hit.t, hit.prim), (1.0, UNIT_PRIM), "{name}: {ray:?}");
            }
            assert_eq!(backend.occluded(&ray), hits, "{name}: {ray:?}");
        }
    }
}

#[test]
fn meshes_without_triangles_are_answered_or_refused_cleanly() {
    let empty = TriangleMesh::default();
    let ray = from_above();
    for name in ["obvhs", "bvh"] {
        let backend = build(name, &empty);
        assert_eq!(backend.intersect(&ray), None, "{name}");
        assert!(!backend.occluded(&ray), "{name}");
    }
    let workers = crate::support::workers(Some(1));
    let error = PARRY3D
        .build(&empty, workers.build_context())
        .err()
        .unwrap();
    assert!(error.to_string().contains("parry3d"), "{error}");
}

#[test]
fn meshes_a_crate_cannot_build_over_are_errors_not_panics() {
    let good = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut bad = good;
    bad[1].x = f32::INFINITY;
    let mesh = TriangleMesh::soup(&[good, bad]);
    let workers = crate::support::workers(Some(1));
    for name in ["obvhs", "bvh"] {
        let backend: BackendName = name.parse().unwrap();
        let error = backend.build(&mesh, workers.build_context()).err().unwrap();
        assert!(
            error.to_string().starts_with(&format!("{name} panicked")),
            "{error}"
        );
    }
    // parry3d builds over it and still finds the good triangle.
    let parry = build("parry3d", &mesh);
    assert_eq!(parry.intersect(&from_above()).unwrap().prim, 0);
}

/// `count` rays from 2 to 4 units outside `mesh`'s bounds towards points
/// well inside random triangles (every barycentric at least 0.05), alike
/// for closest hits and for shadow segments ending before, at about or
/// past the point aimed at.
fn interior_rays(mesh: &TriangleMesh, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng::new(seed);
    let bounds = mesh.bounds();
    let centre = bounds.center();
    let radius = bounds.extent().length() / 2.0;
    (0..count)
        .map(|i| {
            let [p0, p1, p2] = mesh.triangle(rng.below(mesh.triangle_count()));
            let (a, b) = (rng.range(0.05, 0.9), rng.range(0.05, 0.9));
            let (a, b) = if a + b > 0.95 {
                (0.95 - a, 0.95 - b)
            } else {
                (a, b)
            };
            let target =
                (p0.as_dvec3() * (1.0 - a - b) + p1.as_dvec3() * a + p2.as_dvec3() * b).as_vec3();
            let origin = centre + rng.direction() * radius * rng.range_f32(2.0, 4.0);
            let tfar = [f32::INFINITY, 0.5, 1.5][i % 3];
            Ray::segment(origin, target - origin, 0.0, tfar)
        })
        .collect()
}

/// The meshes the agreement test runs on: a grid (shared edges and
/// vertices), a closed sphere, a soup of crossing triangles, the monkey.
fn agreement_meshes() -> Vec<(&'static str, TriangleMesh)> {
    let mut rng = Rng::new(4);
    let soup: Vec<[Vec3; 3]> = (0..2_000)
        .map(|_| {
            let c = rng.point(-1.0, 1.0);
            [(); 3].map(|_| c + rng.point(-0.1, 0.1))
        })
        .collect();
    vec![
        ("grid", grid(16, Placement::IDENTITY)),
        ("icosphere", icosphere(3, Placement::IDENTITY)),
        ("soup", TriangleMesh::soup(&soup)),
        ("monkey", scene::load("monkey").unwrap().mesh),
    ]
}

/// Every ray through `backend` (first) and our BVH, closest and any hit;
/// the log and the referee's judgements on its records.
fn check(
    backend: &dyn Backend,
    ours: &WideBvh,
    mesh: &TriangleMesh,
    rays: &[Ray],
) -> (CheckLog, Vec<Vec<Judgement>>) {
    let checked = Checked::new(vec![backend, ours]);
    rays.par_iter().for_each(|ray| {
        checked.intersect(ray);
        checked.occluded(ray);
    });
    let log = checked.into_log();
    let judgements = log.judge(mesh);
    (log, judgements)
}

#[test]
fn crates_agree_with_ours_wherever_the_referee_is_sure() {
    for (mesh_name, mesh) in agreement_meshes() {
        let rays = interior_rays(&mesh, 3_000, 7);
        let ours = WideBvh::build(&mesh);
        for name in &crates() {
            let backend = build(name, &mesh);
            let (log, judgements) = check(backend.as_ref(), &ours, &mesh, &rays);
            let verdicts = Verdicts::count(&log, &judgements, rays.len() as u64);
            let context = format!("{name} on {mesh_name}: {verdicts:?}");
            assert!(verdicts.judged > 0, "{context}");
            // No wrong decision (hit or miss, triangle, occlusion). A `t`
            // beyond the tolerance on the right triangle is imprecision,
            // counted apart (`t_off`): plain Möller–Trumbore loses digits
            // on grazing hits, and the soup has some.
            assert_eq!(verdicts.backends[0].wrong, 0, "{context}");
            // Our BVH is exact-checked: never wrong where the crate is right.
            let ours = &verdicts.backends[1];
            assert_eq!(ours.wrong + ours.t_off, 0, "{context}");
        }
    }
}

/// A backend with two wrong closest hits planted: on `dropped` it answers
/// a miss, on `pushed` the hit behind the right one.
struct Planted<'a> {
    inner: &'a dyn Backend,
    dropped: Ray,
    pushed: Ray,
}

impl Backend for Planted<'_> {
    fn name(&self) -> String {
        format!("planted {}", self.inner.name())
    }
    fn answers(&self) -> Answers {
        self.inner.answers()
    }
    fn build_time(&self) -> std::time::Duration {
        self.inner.build_time()
    }
    fn bytes(&self) -> Option<usize> {
        self.inner.bytes()
    }
}

impl Intersector for Planted<'_> {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let hit = self.inner.intersect(ray);
        if same_bits(ray, &self.dropped) {
            None
        } else if same_bits(ray, &self.pushed) {
            let first = hit?;
            self.inner.intersect(&Ray {
                tnear: first.t * 1.001,
                ..*ray
            })
        } else {
            hit
        }
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.inner.occluded(ray)
    }
}

fn same_bits(a: &Ray, b: &Ray) -> bool {
    a.inputs().map(f32::to_bits) == b.inputs().map(f32::to_bits)
}

#[test]
fn a_planted_wrong_answer_is_caught_on_exactly_its_ray() {
    // Rays into a closed sphere hit its front, then its back.
    let mesh = icosphere(3, Placement::IDENTITY);
    let rays: Vec<Ray> = interior_rays(&mesh, 600, 11)
        .into_iter()
        .filter(|r| r.tfar == f32::INFINITY)
        .collect();
    let ours = WideBvh::build(&mesh);
    for name in &crates() {
        let backend = build(name, &mesh);
        let planted = Planted {
            inner: backend.as_ref(),
            dropped: rays[10],
            pushed: rays[20],
        };
        assert!(planted.intersect(&rays[20]).is_some(), "{name}");
        let (log, judgements) = check(&planted, &ours, &mesh, &rays);
        let faulted: Vec<(Ray, [Judgement; 2])> = log
            .records
            .iter()
            .zip(&judgements)
            .map(|(r, j)| (r.ray, [j[0], j[1]]))
            .filter(|(_, j)| j.iter().any(|j| !j.is_admissible()))
            .collect();
        // Exactly the two planted rays, both blamed on the planted crate.
        assert_eq!(faulted.len(), 2, "{name}: {faulted:?}");
        for planted_ray in [rays[10], rays[20]] {
            assert!(
                faulted.iter().any(|(r, j)| same_bits(r, &planted_ray)
                    && j[0] == Judgement::Wrong
                    && j[1].is_admissible()),
                "{name}: {faulted:?}"
            );
        }
    }
}

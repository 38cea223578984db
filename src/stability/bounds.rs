//! Case 9: hits exactly at, one ulp inside and one ulp outside `tnear` and
//! `tfar`, and intervals with `tnear > tfar`.

use super::harness::Backends;
use super::{CaseResult, Context};
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use glam::Vec3;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mesh = TriangleMesh::soup(&[[
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(3.0, -1.0, 0.0),
        Vec3::new(-1.0, 3.0, 0.0),
    ]]);
    let backends = Backends::new(context, &mesh)?;
    let mut rng = Rng::new(9);
    let mut rays = Vec::new();
    for _ in 0..context.rays(20_000, 500) {
        let target = Vec3::new(
            rng.range(-0.5, 0.5) as f32,
            rng.range(-0.5, 0.5) as f32,
            0.0,
        );
        let origin = target
            + Vec3::new(
                rng.range(-1.0, 1.0) as f32,
                rng.range(-1.0, 1.0) as f32,
                rng.range(0.1, 4.0) as f32,
            );
        let dir = target - origin;
        // Where our tracer puts the hit: the bounds are set around it.
        let t = Ray::new(origin, dir);
        let Some(hit) = crate::trace::Intersector::intersect(&backends.ours, &t) else {
            continue;
        };
        for near in [hit.t.next_down(), hit.t, hit.t.next_up()] {
            rays.push(Ray::segment(origin, dir, near, f32::INFINITY));
        }
        for far in [hit.t.next_down(), hit.t, hit.t.next_up()] {
            rays.push(Ray::segment(origin, dir, 0.0, far));
        }
        rays.push(Ray::segment(origin, dir, hit.t, hit.t));
        rays.push(Ray::segment(
            origin,
            dir,
            hit.t.next_up(),
            hit.t.next_down(),
        ));
        rays.push(Ray::segment(origin, dir, 2.0 * hit.t, 0.5 * hit.t));
    }
    Ok(CaseResult::judged(
        "tnear_tfar_boundaries",
        backends.trace(&rays),
    ))
}

//! Case 13: long rays and unnormalized directions. Hits at `t` from 1e3 to
//! 1e18 (a triangle scaled with its distance); directions scaled by powers
//! of two from about 1e-6 to 1e6, under which `t` must scale exactly and
//! the primID stay.

use super::harness::Backends;
use super::{CaseDetails, CaseResult, Context};
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use crate::results::Verdicts;
use crate::trace::Intersector;
use glam::Vec3;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut rng = Rng::new(13);
    let mut total = Verdicts::default();
    let mut scaling_violations = 0u64;
    for k in [3, 6, 9, 12, 15, 18] {
        let d = 10f32.powi(k);
        let corner = |x: f32, y: f32| Vec3::new(x * d * 0.5, y * d * 0.5, d);
        let mesh = TriangleMesh::soup(&[
            [corner(-1.0, -1.0), corner(1.0, -1.0), corner(-1.0, 1.0)],
            [corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)],
        ]);
        let backends = Backends::new(context, &mesh)?;
        let mut rays = Vec::new();
        for _ in 0..context.rays(5_000, 100) {
            let dir = Vec3::new(
                rng.range(-0.4, 0.4) as f32,
                rng.range(-0.4, 0.4) as f32,
                1.0,
            );
            let base = Ray::new(Vec3::ZERO, dir);
            let reference = backends.ours.intersect(&base);
            for e in (-20..=20).step_by(5) {
                let scale = 2f32.powi(e);
                let scaled = Ray::new(Vec3::ZERO, dir * scale);
                let hit = backends.ours.intersect(&scaled);
                let same = match (reference, hit) {
                    (Some(a), Some(b)) => a.prim == b.prim && a.t == b.t * scale,
                    (None, None) => true,
                    _ => false,
                };
                scaling_violations += !same as u64;
                rays.push(scaled);
            }
        }
        total += &backends.trace(&rays);
    }
    let mut result = CaseResult::judged("long_rays_and_unnormalized_directions", total);
    result.details = CaseDetails::Scaling {
        t_scaling_violations: scaling_violations,
    };
    Ok(result)
}

//! Case 6: degenerate triangles (collinear corners, a repeated corner, all
//! three equal) and one-ulp needles, hit by rays aimed at and around them.
//! A degenerate triangle is never hit; a needle may be.

use super::harness::Backends;
use super::{CaseResult, Context};
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use glam::Vec3;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let ulp = |x: f32| x.next_up() - x;
    let p = Vec3::new(0.3, 0.7, 0.2);
    let triangles = [
        [Vec3::ZERO, Vec3::ONE, Vec3::splat(2.0)],
        [
            Vec3::ZERO,
            Vec3::new(1.0, 2.0, 0.0),
            Vec3::new(0.5, 1.0, 0.0),
        ],
        [p, p, Vec3::new(1.0, 0.0, 0.5)],
        [p, p, p],
        [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, f32::MIN_POSITIVE, 0.0),
        ],
        [
            Vec3::new(-1.0, 0.5, 1.0),
            Vec3::new(1.0, 0.5, 1.0),
            Vec3::new(0.0, 0.5 + ulp(0.5), 1.0),
        ],
        [
            Vec3::new(3.0, -1.0, 0.0),
            Vec3::new(3.0, 1.0, 0.0),
            Vec3::new(3.0 + ulp(3.0), 0.0, 0.0),
        ],
    ];
    let mesh = TriangleMesh::soup(&triangles);
    let backends = Backends::new(context, &mesh)?;
    let mut rng = Rng::new(6);
    let rays: Vec<Ray> = (0..context.rays(100_000, 3_000))
        .map(|_| {
            let [a, b, c] = triangles[rng.below(triangles.len())];
            let on = a.lerp(b, rng.unit() as f32).lerp(c, rng.unit() as f32);
            let origin = on + 2.0 * rng.direction();
            Ray::new(origin, on - origin)
        })
        .collect();
    Ok(CaseResult::judged(
        "degenerate_triangles",
        backends.trace(&rays),
    ))
}

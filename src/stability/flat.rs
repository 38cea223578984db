//! Case 4: axis-aligned triangles, so every node box is flat; rays at
//! incidence angles from 90° down to 1e-6 rad, and rays in the plane. The
//! BVH must answer as the loop over all triangles does.

use super::harness::Backends;
use super::shapes::{Placement, grid};
use super::traversal::traversal_mismatches;
use super::{CaseResult, Context};
use crate::geometry::Ray;
use crate::random::Rng;
use glam::{DVec3, Vec3};

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mesh = grid(
        32,
        Placement {
            scale: 1.0 / 8.0,
            offset: DVec3::new(-2.0, -2.0, 0.0),
        },
    );
    let backends = Backends::new(context, &mesh)?;
    let mut rng = Rng::new(4);
    let angles: Vec<f64> = (0..=6)
        .map(|k| 10f64.powi(-k))
        .chain([std::f64::consts::FRAC_PI_2, 0.0])
        .collect();
    let per_angle = context.rays(20_000, 500);
    let mut rays = Vec::new();
    for &angle in &angles {
        for _ in 0..per_angle {
            let azimuth = rng.range(0.0, std::f64::consts::TAU);
            let dir = DVec3::new(
                angle.cos() * azimuth.cos(),
                angle.cos() * azimuth.sin(),
                -angle.sin(),
            );
            let target = DVec3::new(rng.range(-1.9, 1.9), rng.range(-1.9, 1.9), 0.0);
            let origin = (target - dir * rng.range(0.1, 3.0)).as_vec3();
            rays.push(Ray::new(origin, dir.as_vec3()));
        }
    }
    // Rays exactly in the plane z = 0, along and across the grid lines.
    rays.extend((0..per_angle).map(|_| {
        Ray::new(
            Vec3::new(-3.0, rng.range(-2.0, 2.0) as f32, 0.0),
            Vec3::new(1.0, rng.range(-1.0, 1.0) as f32, 0.0),
        )
    }));
    let mut result = CaseResult::judged("flat_boxes", backends.trace(&rays));
    result.traversal_mismatches = Some(traversal_mismatches(&backends, &rays));
    Ok(result)
}

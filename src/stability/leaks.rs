//! Case 1: rays from inside closed spheres, aimed at vertices and at points
//! on shared edges, at the origin and far from it. Every ray must hit; one
//! that does not has leaked through the surface.

use super::harness::Backends;
use super::shapes::{Placement, icosphere, uv_sphere};
use super::{CaseDetails, CaseResult, Context, Trial};
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use crate::results::Verdicts;
use glam::DVec3;

/// The placements of the issue: the origin, Embree's own watertightness
/// test centre, and 1e6; radii keep the vertices well apart in f32.
pub const PLACEMENTS: [(f64, [f64; 3]); 3] = [
    (1.0, [0.0; 3]),
    (2.0, [148376.0, 1234.0, -223423.0]),
    (100.0, [1e6, 1e6, 1e6]),
];

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let per_mesh = context.rays(170_000, 2_000);
    let mut total = Verdicts::default();
    let mut trials = Vec::new();
    for (radius, centre) in PLACEMENTS {
        let placement = Placement {
            scale: radius,
            offset: DVec3::from_array(centre),
        };
        for (shape, mesh) in [
            ("uv_sphere", uv_sphere(48, 96, placement)),
            ("icosphere", icosphere(4, placement)),
        ] {
            let verdicts = leak_trial(context, &mesh, placement, per_mesh, 1)?;
            total += &verdicts;
            trials.push(Trial {
                label: format!(
                    "{shape}, radius {radius}, centre ({}, {}, {})",
                    centre[0], centre[1], centre[2]
                ),
                verdicts,
            });
        }
    }
    let mut result = CaseResult::judged("closed_mesh_leaks", total).with_leaks();
    result.details = CaseDetails::Trials { trials };
    Ok(result)
}

/// `count` rays from random points inside the closed `mesh` (placed by
/// `placement` around the unit sphere): a third aimed at vertices, a third
/// at points along edges, a third in random directions.
pub fn leak_trial(
    context: &Context,
    mesh: &TriangleMesh,
    placement: Placement,
    count: usize,
    seed: u64,
) -> anyhow::Result<Verdicts> {
    let backends = Backends::new(context, mesh)?;
    let mut rng = Rng::new(seed);
    let rays: Vec<Ray> = (0..count)
        .map(|i| {
            let inside = DVec3::new(
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
                rng.range(-0.5, 0.5),
            );
            let origin = placement.apply(inside);
            let [a, b, _] = mesh.triangle(rng.below(mesh.triangle_count()));
            let target = match i % 3 {
                0 => a,
                1 => a.lerp(b, rng.unit() as f32),
                _ => origin + rng.direction(),
            };
            Ray::new(origin, target - origin)
        })
        .collect();
    Ok(backends.trace_must_hit(&rays))
}

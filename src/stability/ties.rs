//! Case 12: ties. 10,000 identical triangles, coplanar overlapping quads
//! and two touching spheres. Ties give the same `t` on every backend and,
//! on ours, the same (lowest) primID on every run.

use super::harness::Backends;
use super::shapes::{Placement, grid, icosphere};
use super::{CaseDetails, CaseResult, Context};
use crate::check::exact::Oracle;
use crate::geometry::{Ray, TriangleMesh};
use crate::random::Rng;
use crate::results::Verdicts;
use crate::trace::Intersector;
use glam::{DVec3, Vec3};

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let identical = TriangleMesh::soup(&vec![
        [
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(2.0, -1.0, 0.0),
            Vec3::new(-1.0, 2.0, 0.0)
        ];
        10_000
    ]);
    let mut overlapping = grid(
        8,
        Placement {
            scale: 0.5,
            offset: DVec3::new(-2.0, -2.0, 0.0),
        },
    );
    overlapping.append(
        &grid(
            8,
            Placement {
                scale: 0.5,
                offset: DVec3::new(-1.75, -1.75, 0.0),
            },
        ),
        0,
    );
    let mut touching = icosphere(
        3,
        Placement {
            scale: 1.0,
            offset: DVec3::new(-1.0, 0.0, 0.0),
        },
    );
    touching.append(
        &icosphere(
            3,
            Placement {
                scale: 1.0,
                offset: DVec3::new(1.0, 0.0, 0.0),
            },
        ),
        0,
    );
    let mut rng = Rng::new(12);
    let mut total = Verdicts::default();
    let mut not_lowest = 0;
    for (mesh, count, near_contact) in [
        (&identical, context.rays(200, 20), false),
        (&overlapping, context.rays(50_000, 1_000), false),
        (&touching, context.rays(50_000, 1_000), true),
    ] {
        let backends = Backends::new(context, mesh)?;
        let rays: Vec<Ray> = (0..count)
            .map(|_| {
                let (a, b) = (rng.range(-0.5, 0.5) as f32, rng.range(-0.5, 0.5) as f32);
                let target = if near_contact {
                    Vec3::new(0.0, a, b)
                } else {
                    Vec3::new(a, b, 0.0)
                };
                let origin = target + 3.0 * rng.direction();
                Ray::new(origin, target - origin)
            })
            .collect();
        not_lowest += lowest_prim_violations(&backends.ours, mesh, &rays);
        total += &backends.trace(&rays);
    }
    let mut result = CaseResult::judged("ties", total);
    result.details = CaseDetails::Ties {
        tie_not_lowest_prim: not_lowest,
    };
    Ok(result)
}

/// Rays whose exact closest hit is a tie and on which our answer is not
/// the tie's lowest primID (the rule that makes it deterministic).
fn lowest_prim_violations(ours: &dyn Intersector, mesh: &TriangleMesh, rays: &[Ray]) -> u64 {
    let oracle = Oracle::new(mesh);
    rays.iter()
        .filter(|ray| {
            let Some((_, tied)) = oracle.nearest(ray) else {
                return false;
            };
            tied.len() > 1
                && ours
                    .intersect(ray)
                    .is_some_and(|h| tied.contains(&h.prim) && h.prim != tied[0])
        })
        .count() as u64
}

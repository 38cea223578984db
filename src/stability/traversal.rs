//! Case 14: traversal against brute force. Random and hard-case rays
//! through the BVH and through the loop over all triangles with the same
//! triangle test: the answers must be identical to the bit.

use super::harness::Backends;
use super::shapes::{Placement, grid, icosphere};
use super::{CaseResult, Context};
use crate::bvh::Bvh;
use crate::geometry::{Hit, Ray, TriangleMesh};
use crate::random::Rng;
use crate::trace::Intersector;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut rng = Rng::new(14);
    let random: Vec<[Vec3; 3]> = (0..400)
        .map(|_| {
            let centre = 4.0 * rng.direction();
            [
                centre + 0.3 * rng.direction(),
                centre + 0.3 * rng.direction(),
                centre + 0.3 * rng.direction(),
            ]
        })
        .collect();
    let mut mesh = TriangleMesh::soup(&random);
    mesh.append(
        &icosphere(
            2,
            Placement {
                scale: 1.5,
                ..Placement::IDENTITY
            },
        ),
        0,
    );
    mesh.append(
        &grid(
            8,
            Placement {
                scale: 0.5,
                offset: DVec3::new(-2.0, -2.0, 0.0),
            },
        ),
        0,
    );
    let backends = Backends::new(context, &mesh)?;
    let rays: Vec<Ray> = (0..context.rays(1_000_000, 10_000))
        .map(|i| {
            let origin = 6.0 * rng.direction() * rng.unit() as f32;
            match i % 4 {
                // Aimed at a vertex: the hard case.
                0 => Ray::new(
                    origin,
                    mesh.positions[rng.below(mesh.positions.len())] - origin,
                ),
                // Axis-parallel.
                1 => Ray::new(
                    origin,
                    Vec3::AXES[rng.below(3)] * if rng.unit() < 0.5 { 1.0 } else { -1.0 },
                ),
                _ => Ray::new(origin, rng.direction()),
            }
        })
        .collect();
    // The referee's exact scan is costly on a million rays; it judges a
    // deterministic tenth of them.
    let judged: Vec<Ray> = rays.iter().step_by(10).copied().collect();
    let mut result = CaseResult::judged("traversal_against_brute_force", backends.trace(&judged));
    result.rays = rays.len() as u64;
    result.traversal_mismatches = Some(traversal_mismatches(&backends, &rays));
    Ok(result)
}

/// Queries on which our wide or binary BVH's traversal and the loop over
/// all triangles give answers that differ in any bit (closest hit or any
/// hit).
pub fn traversal_mismatches(backends: &Backends, rays: &[Ray]) -> u64 {
    let brute_force = &backends.binary;
    [&backends.ours as &dyn Intersector, &backends.binary]
        .into_iter()
        .map(|tracer| mismatches(tracer, brute_force, rays))
        .sum()
}

/// Queries on which `tracer` and `brute_force`'s loop over all triangles
/// differ in any bit.
fn mismatches(tracer: &dyn Intersector, brute_force: &Bvh, rays: &[Ray]) -> u64 {
    let bits = |h: Option<Hit>| {
        h.map(|h| {
            (
                h.prim,
                h.t.to_bits(),
                h.u.to_bits(),
                h.v.to_bits(),
                h.ng.to_array().map(f32::to_bits),
            )
        })
    };
    rays.par_iter()
        .map(|ray| {
            let closest =
                bits(tracer.intersect(ray)) != bits(brute_force.intersect_brute_force(ray));
            let any = tracer.occluded(ray) != brute_force.occluded_brute_force(ray);
            closest as u64 + any as u64
        })
        .sum()
}

//! Case 2: a plane of 200×200 quads (Embree's own watertightness test
//! plane, 12×12 units); rays from above through its interior vertices and
//! points on its interior grid lines and diagonals. Every ray must hit.

use super::harness::Backends;
use super::shapes::{Placement, grid};
use super::{CaseResult, Context};
use crate::geometry::Ray;
use crate::random::Rng;
use glam::{DVec3, Vec3};

const QUADS: u32 = 200;

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let placement = Placement {
        scale: 12.0 / QUADS as f64,
        offset: DVec3::new(-6.0, -6.0, 0.0),
    };
    let mesh = grid(QUADS, placement);
    let backends = Backends::new(context, &mesh)?;
    let mut rng = Rng::new(2);
    let vertex = |i: u32, j: u32| mesh.positions[(i * (QUADS + 1) + j) as usize];
    let rays: Vec<Ray> = (0..context.rays(300_000, 5_000))
        .map(|k| {
            let (i, j) = (
                1 + rng.below(QUADS as usize - 2) as u32,
                1 + rng.below(QUADS as usize - 2) as u32,
            );
            let next = match k % 4 {
                0 => vertex(i, j),
                1 => vertex(i, j + 1),
                2 => vertex(i + 1, j),
                _ => vertex(i + 1, j + 1),
            };
            let target = vertex(i, j).lerp(next, rng.unit() as f32);
            let origin = target
                + Vec3::new(
                    rng.range(-3.0, 3.0) as f32,
                    rng.range(-3.0, 3.0) as f32,
                    rng.range(0.5, 4.0) as f32,
                );
            Ray::new(origin, target - origin)
        })
        .collect();
    Ok(CaseResult::judged("grid_edges", backends.trace_must_hit(&rays)).with_leaks())
}

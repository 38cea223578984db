//! Case 3: axis-parallel rays and signed zeros. Every direction whose
//! components are each 0, -0, +1 or -1, from origins on the faces, edges
//! and corners of a cube and one ulp either side of them.

use super::harness::Backends;
use super::shapes::{Placement, uv_sphere};
use super::{CaseResult, Context};
use crate::geometry::{Ray, TriangleMesh};
use glam::Vec3;

/// A cube [-1, 1]³ of twelve triangles, wound outwards.
pub fn cube() -> TriangleMesh {
    let corner = |i: u32| {
        Vec3::new(
            if i & 1 == 0 { -1.0 } else { 1.0 },
            if i & 2 == 0 { -1.0 } else { 1.0 },
            if i & 4 == 0 { -1.0 } else { 1.0 },
        )
    };
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let indices = quads
        .iter()
        .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
        .collect();
    TriangleMesh {
        positions: (0..8).map(corner).collect(),
        indices,
        materials: vec![0; 12],
        ..Default::default()
    }
}

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut mesh = cube();
    // A small sphere inside, so rays from inside also have something to hit.
    mesh.append(
        &uv_sphere(
            6,
            12,
            Placement {
                scale: 0.25,
                ..Placement::IDENTITY
            },
        ),
        0,
    );
    let backends = Backends::new(context, &mesh)?;
    let coordinates = [
        -2.0,
        (-1.0f32).next_down(),
        -1.0,
        (-1.0f32).next_up(),
        -0.0,
        0.0,
        0.5,
        1.0f32.next_down(),
        1.0,
        1.0f32.next_up(),
        2.0,
    ];
    let components = [0.0, -0.0, 1.0, -1.0];
    let mut rays = Vec::new();
    for &x in &coordinates {
        for &y in &coordinates {
            for &z in &coordinates {
                for d in 0..64 {
                    let dir = Vec3::new(
                        components[d & 3],
                        components[(d >> 2) & 3],
                        components[d >> 4],
                    );
                    rays.push(Ray::new(Vec3::new(x, y, z), dir));
                }
            }
        }
    }
    Ok(CaseResult::judged(
        "axis_parallel_and_signed_zeros",
        backends.trace(&rays),
    ))
}

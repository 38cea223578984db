//! Meshes and rays for the BVH tests, from a seeded generator so every run
//! sees the same cases.

use super::{BuildOptions, Builder};
use crate::geometry::{Ray, TriangleMesh};
use glam::Vec3;

pub use crate::random::Rng;

/// `count` random triangles of size up to `size` in the cube [-1, 1]³.
pub fn random_soup(count: usize, size: f32, rng: &mut Rng) -> TriangleMesh {
    let triangles: Vec<[Vec3; 3]> = (0..count)
        .map(|_| {
            let centre = rng.point(-1.0, 1.0);
            [(); 3].map(|_| centre + rng.point(-size, size))
        })
        .collect();
    TriangleMesh::soup(&triangles)
}

/// An `n` × `n` grid of quads in the unit square of the z = 0 plane, each
/// split in two; every inner edge is shared.
pub fn grid(n: u32) -> TriangleMesh {
    let positions = (0..=n)
        .flat_map(|y| {
            (0..=n).map(move |x| Vec3::new(x as f32 / n as f32, y as f32 / n as f32, 0.0))
        })
        .collect();
    let vertex = |x: u32, y: u32| y * (n + 1) + x;
    let indices: Vec<[u32; 3]> = (0..n)
        .flat_map(|y| (0..n).map(move |x| (x, y)))
        .flat_map(|(x, y)| {
            let (a, b, c, d) = (
                vertex(x, y),
                vertex(x + 1, y),
                vertex(x + 1, y + 1),
                vertex(x, y + 1),
            );
            [[a, b, c], [a, c, d]]
        })
        .collect();
    TriangleMesh::new(positions, indices)
}

/// A closed UV sphere of `rings` × `segments` quads (triangles at the
/// poles), each split in two.
pub fn sphere(centre: Vec3, radius: f32, rings: u32, segments: u32) -> TriangleMesh {
    use std::f32::consts::{PI, TAU};
    let mut positions = vec![centre + radius * Vec3::Z, centre - radius * Vec3::Z];
    for ring in 1..rings {
        let theta = PI * ring as f32 / rings as f32;
        for segment in 0..segments {
            let phi = TAU * segment as f32 / segments as f32;
            positions.push(
                centre
                    + radius
                        * Vec3::new(
                            theta.sin() * phi.cos(),
                            theta.sin() * phi.sin(),
                            theta.cos(),
                        ),
            );
        }
    }
    let ring_vertex = |ring: u32, segment: u32| 2 + (ring - 1) * segments + segment % segments;
    let mut indices = Vec::new();
    for segment in 0..segments {
        indices.push([0, ring_vertex(1, segment), ring_vertex(1, segment + 1)]);
        indices.push([
            1,
            ring_vertex(rings - 1, segment + 1),
            ring_vertex(rings - 1, segment),
        ]);
        for ring in 1..rings - 1 {
            let (a, b) = (ring_vertex(ring, segment), ring_vertex(ring, segment + 1));
            let (c, d) = (
                ring_vertex(ring + 1, segment + 1),
                ring_vertex(ring + 1, segment),
            );
            indices.extend([[a, d, c], [a, c, b]]);
        }
    }
    TriangleMesh::new(positions, indices)
}

/// The prim ids at which [`tie_mesh`] places the same triangle, and the
/// lowest of them, which a closest hit through it must report.
pub const TIED_PRIMS: [usize; 3] = [417, 38, 250];
pub const LOWEST_TIED_PRIM: u32 = 38;

/// 500 small random triangles above z = 3, three of them replaced by the
/// unit triangle in z = 0 (at [`TIED_PRIMS`]); the ray up through (0.2, 0.2)
/// from z = -1 meets the three at `t = 1`, before any other.
pub fn tie_mesh(rng: &mut Rng) -> (TriangleMesh, Ray) {
    let mut triangles: Vec<[Vec3; 3]> = (0..500)
        .map(|_| {
            let c = rng.point(-1.0, 1.0) + 3.0 * Vec3::Z;
            [c, c + 0.1 * Vec3::X, c + 0.1 * Vec3::Y]
        })
        .collect();
    for prim in TIED_PRIMS {
        triangles[prim] = [Vec3::ZERO, Vec3::X, Vec3::Y];
    }
    let ray = Ray::new(Vec3::new(0.2, 0.2, -1.0), Vec3::Z);
    (TriangleMesh::soup(&triangles), ray)
}

/// Rays from random points around the unit cube towards random points in
/// it, with a mix of intervals and some axis-aligned directions.
pub fn random_rays(count: usize, rng: &mut Rng) -> Vec<Ray> {
    (0..count)
        .map(|i| {
            let origin = rng.point(-3.0, 3.0);
            let mut dir = rng.point(-1.0, 1.0) - origin;
            if i % 7 == 0 {
                // Zero out one or two components.
                dir[i % 3] = 0.0;
                if i % 2 == 0 {
                    dir[(i + 1) % 3] = 0.0;
                }
            }
            let (tnear, tfar) = match i % 4 {
                0 => (0.0, f32::INFINITY),
                1 => (rng.range_f32(0.0, 1.0), rng.range_f32(1.0, 2.0)),
                2 => (0.0, rng.range_f32(0.5, 1.5)),
                _ => (rng.range_f32(0.0, 0.5), f32::INFINITY),
            };
            Ray::segment(origin, dir, tnear, tfar)
        })
        .collect()
}

/// Both builders' default options plus some with tight limits.
pub fn option_sets() -> Vec<BuildOptions> {
    let mut sets = vec![BuildOptions::median(), BuildOptions::sah()];
    for builder in [Builder::Median, Builder::Sah] {
        sets.push(BuildOptions {
            builder,
            max_depth: 3,
            max_leaf_size: 2,
            sah_bins: 4,
        });
        sets.push(BuildOptions {
            builder,
            max_depth: 200,
            max_leaf_size: 1,
            sah_bins: 1000,
        });
    }
    sets
}

/// Variants of `ok` that can hit nothing: a zero or NaN direction, an
/// infinite origin, a NaN bound, `tnear > tfar`.
pub fn untraceable_variants(ok: Ray) -> [Ray; 6] {
    let nan = f32::NAN;
    [
        Ray {
            dir: Vec3::ZERO,
            ..ok
        },
        Ray {
            dir: Vec3::new(nan, 0.0, 1.0),
            ..ok
        },
        Ray {
            origin: Vec3::new(0.0, f32::INFINITY, -5.0),
            ..ok
        },
        Ray { tnear: nan, ..ok },
        Ray { tfar: nan, ..ok },
        Ray {
            tnear: 2.0,
            tfar: 1.0,
            ..ok
        },
    ]
}

//! The meshes the stability cases are made of, built in f64 and rounded to
//! f32 once, with shared vertices so closed shapes are closed exactly.

use crate::geometry::TriangleMesh;
use glam::{DVec3, Vec3};
use std::collections::HashMap;

/// A placement: `p · scale + offset`, evaluated in f64, rounded once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub scale: f64,
    pub offset: DVec3,
}

impl Placement {
    pub const IDENTITY: Placement = Placement {
        scale: 1.0,
        offset: DVec3::ZERO,
    };

    pub fn apply(&self, p: DVec3) -> Vec3 {
        (p * self.scale + self.offset).as_vec3()
    }

    /// The unit-scale point a placed point comes from, in f64.
    pub fn unapply(&self, p: DVec3) -> DVec3 {
        (p - self.offset) / self.scale
    }
}

/// A latitude/longitude sphere of unit radius with single-vertex poles.
pub fn uv_sphere(rings: u32, segments: u32, placement: Placement) -> TriangleMesh {
    let mut positions = vec![placement.apply(DVec3::Z)];
    for ring in 1..rings {
        let theta = std::f64::consts::PI * ring as f64 / rings as f64;
        for s in 0..segments {
            let phi = std::f64::consts::TAU * s as f64 / segments as f64;
            let p = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            positions.push(placement.apply(p));
        }
    }
    positions.push(placement.apply(DVec3::NEG_Z));
    let south = positions.len() as u32 - 1;
    let at = |ring: u32, s: u32| 1 + (ring - 1) * segments + s % segments;
    let mut indices = Vec::new();
    for s in 0..segments {
        indices.push([0, at(1, s), at(1, s + 1)]);
        indices.push([south, at(rings - 1, s + 1), at(rings - 1, s)]);
        for ring in 1..rings - 1 {
            let (a, b, c, d) = (
                at(ring, s),
                at(ring + 1, s),
                at(ring + 1, s + 1),
                at(ring, s + 1),
            );
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    TriangleMesh::new(positions, indices)
}

/// An icosahedron subdivided `levels` times, projected to the unit sphere.
pub fn icosphere(levels: u32, placement: Placement) -> TriangleMesh {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut points: Vec<DVec3> = [
        (-1.0, g, 0.0),
        (1.0, g, 0.0),
        (-1.0, -g, 0.0),
        (1.0, -g, 0.0),
        (0.0, -1.0, g),
        (0.0, 1.0, g),
        (0.0, -1.0, -g),
        (0.0, 1.0, -g),
        (g, 0.0, -1.0),
        (g, 0.0, 1.0),
        (-g, 0.0, -1.0),
        (-g, 0.0, 1.0),
    ]
    .map(|(x, y, z)| DVec3::new(x, y, z).normalize())
    .to_vec();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push(((points[a as usize] + points[b as usize]) / 2.0).normalize());
                points.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (midpoint(a, b), midpoint(b, c), midpoint(c, a));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    TriangleMesh::new(
        points.into_iter().map(|p| placement.apply(p)).collect(),
        faces,
    )
}

/// An `n`×`n` grid of unit quads in the plane z = 0, each split in two.
pub fn grid(n: u32, placement: Placement) -> TriangleMesh {
    let at = |i: u32, j: u32| i * (n + 1) + j;
    let positions = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| DVec3::new(j as f64, i as f64, 0.0)))
        .map(|p| placement.apply(p))
        .collect();
    let indices = (0..n)
        .flat_map(|i| {
            (0..n).flat_map(move |j| {
                [
                    [at(i, j), at(i, j + 1), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i + 1, j)],
                ]
            })
        })
        .collect();
    TriangleMesh::new(positions, indices)
}

/// A closed double cone ("fan") of `segments` triangles per side around an
/// axis of length `length` and radius 1: aspect ratio about `length`.
pub fn sliver_spindle(segments: u32, length: f64, placement: Placement) -> TriangleMesh {
    let mut positions = vec![
        placement.apply(DVec3::new(0.0, 0.0, length)),
        placement.apply(DVec3::new(0.0, 0.0, -length)),
    ];
    for s in 0..segments {
        let phi = std::f64::consts::TAU * s as f64 / segments as f64;
        positions.push(placement.apply(DVec3::new(phi.cos(), phi.sin(), 0.0)));
    }
    let rim = |s: u32| 2 + s % segments;
    let indices = (0..segments)
        .flat_map(|s| [[0, rim(s), rim(s + 1)], [1, rim(s + 1), rim(s)]])
        .collect();
    TriangleMesh::new(positions, indices)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Every edge of a closed, consistently wound mesh is used once in
    /// each direction.
    fn is_closed(mesh: &TriangleMesh) -> bool {
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for &[a, b, c] in &mesh.indices {
            for (p, q) in [(a, b), (b, c), (c, a)] {
                *edges.entry((p.min(q), p.max(q))).or_default() += if p < q { 1 } else { -1 };
            }
        }
        edges.values().all(|&v| v == 0)
    }

    #[test]
    fn spheres_and_spindles_are_closed() {
        assert!(is_closed(&uv_sphere(8, 16, Placement::IDENTITY)));
        assert!(is_closed(&icosphere(2, Placement::IDENTITY)));
        assert!(is_closed(&sliver_spindle(12, 1e3, Placement::IDENTITY)));
        assert_eq!(icosphere(2, Placement::IDENTITY).triangle_count(), 320);
        assert_eq!(grid(3, Placement::IDENTITY).triangle_count(), 18);
    }
}

//! Integration tests of the Embree wrapper against the real library.

mod build_errors;
mod device;
mod float_mode;
mod queries;
mod scene_builds;
mod statistics;

use raycheck_reference::{Device, DeviceConfig, RayQuery};

/// An owned mesh for tests; `as_ref` lends it as Embree input.
pub struct TestMesh {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
}

impl TestMesh {
    pub fn as_ref(&self) -> raycheck_reference::TriangleMeshRef<'_> {
        raycheck_reference::TriangleMeshRef {
            positions: &self.positions,
            indices: &self.indices,
        }
    }
}

/// An `n` x `n` grid of unit squares in the plane z = `z`, two triangles
/// per square: square (i, j) holds triangles `2 (i n + j)` and `2 (i n + j) + 1`.
pub fn grid(n: u32, z: f32) -> TestMesh {
    let positions = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| [i as f32, j as f32, z]))
        .collect();
    let corner = |i: u32, j: u32| i * (n + 1) + j;
    let indices = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            let (a, b, c, d) = (
                corner(i, j),
                corner(i + 1, j),
                corner(i, j + 1),
                corner(i + 1, j + 1),
            );
            [[a, b, c], [b, d, c]]
        })
        .collect();
    TestMesh { positions, indices }
}

/// A UV sphere of `rings` x `segments` quads split into triangles.
pub fn sphere(center: [f32; 3], radius: f32, rings: u32, segments: u32) -> TestMesh {
    let mut positions = Vec::new();
    for ring in 0..=rings {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        for segment in 0..=segments {
            let phi = std::f32::consts::TAU * segment as f32 / segments as f32;
            positions.push([
                center[0] + radius * theta.sin() * phi.cos(),
                center[1] + radius * theta.sin() * phi.sin(),
                center[2] + radius * theta.cos(),
            ]);
        }
    }
    let corner = |ring: u32, segment: u32| ring * (segments + 1) + segment;
    let mut indices = Vec::new();
    for ring in 0..rings {
        for segment in 0..segments {
            let (a, b) = (corner(ring, segment), corner(ring, segment + 1));
            let (c, d) = (corner(ring + 1, segment), corner(ring + 1, segment + 1));
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    TestMesh { positions, indices }
}

pub fn device() -> Device {
    raycheck_reference::enable_flush_to_zero_and_denormals_are_zero();
    Device::new(&DeviceConfig {
        threads: Some(2),
        ..DeviceConfig::default()
    })
    .expect("Embree creates a device")
}

/// A ray straight down (-z) from height 10 above (x, y).
pub fn down_at(x: f32, y: f32) -> RayQuery {
    RayQuery {
        origin: [x, y, 10.0],
        dir: [0.0, 0.0, -1.0],
        tnear: 0.0,
        tfar: f32::INFINITY,
    }
}

/// `|a - b| <= tolerance * max(1, |b|)`.
pub fn close(a: f32, b: f32, tolerance: f32) -> bool {
    (a - b).abs() <= tolerance * b.abs().max(1.0)
}

//! Geometry shared by every backend: rays, hits, boxes, meshes and the
//! watertight ray/triangle test.

pub mod aabb;
pub mod mesh;
pub mod offset;
pub mod ray;
pub mod triangle;

pub use aabb::Aabb;
pub use mesh::TriangleMesh;
pub use ray::{Hit, Ray};

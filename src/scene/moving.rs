//! Meshes that move during the shutter interval (motion blur).

use crate::geometry::TriangleMesh;
use glam::Vec3;

/// A mesh translating with a constant velocity: at shutter time `τ` in
/// `[0, 1)` its vertices are at `position + τ·velocity`. It keeps its own
/// triangle ids (from 0) and indexes the scene's materials.
#[derive(Clone, Debug, PartialEq)]
pub struct MovingMesh {
    pub mesh: TriangleMesh,
    /// Displacement over the whole shutter interval.
    pub velocity: Vec3,
}

//! Scenes: manifests, mesh loaders, packaged assets, cameras, lights and materials.

pub mod camera;
pub mod error;
pub mod feature;
mod gzip;
pub mod light;
pub mod material;
pub mod ply;
mod text;

pub use camera::Camera;
pub use error::SceneError;
pub use feature::Feature;
pub use light::Light;
pub use material::Material;

use crate::geometry::TriangleMesh;

/// A mesh as one loader produced it, with the materials its triangles index.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    pub mesh: TriangleMesh,
    pub materials: Vec<Material>,
}

//! A borrowed triangle mesh, the input of every Embree scene build.

use crate::EmbreeError;

/// One triangle mesh: vertex positions and, per triangle, three indices into
/// them. A triangle's `primID` in Embree is its index in `indices`.
#[derive(Clone, Copy, Debug)]
pub struct TriangleMeshRef<'a> {
    pub positions: &'a [[f32; 3]],
    pub indices: &'a [[u32; 3]],
}

impl TriangleMeshRef<'_> {
    /// Refuses a triangle that names a missing vertex (Embree would drop it
    /// without reporting an error). `mesh` is the mesh's position in the scene.
    pub(crate) fn check_indices(&self, mesh: usize) -> Result<(), EmbreeError> {
        let vertex_count = self.positions.len();
        for (triangle, corners) in self.indices.iter().enumerate() {
            if let Some(&index) = corners.iter().find(|&&i| i as usize >= vertex_count) {
                return Err(EmbreeError::IndexOutOfRange {
                    mesh,
                    triangle,
                    index,
                    vertex_count,
                });
            }
        }
        Ok(())
    }
}

//! Smooth shading normals (Phong 1975): the vertex normals interpolated
//! with the hit's barycentrics. A zero vertex normal means the mesh has
//! none there, and the geometric normal is used instead.

use crate::geometry::TriangleMesh;
use glam::Vec3;

/// The interpolated normal of triangle `prim` at barycentrics (`u`, `v`),
/// turned to the side of `facing` (the geometric normal facing the viewer);
/// `None` when the mesh has no usable normal there.
pub fn shading_normal(
    mesh: &TriangleMesh,
    prim: u32,
    u: f32,
    v: f32,
    facing: Vec3,
) -> Option<Vec3> {
    let normals = mesh.normals.as_ref()?;
    let [a, b, c] = mesh.indices[prim as usize].map(|i| normals[i as usize]);
    if [a, b, c].contains(&Vec3::ZERO) {
        return None;
    }
    let n = ((1.0 - u - v) * a + u * b + v * c).try_normalize()?;
    Some(if n.dot(facing) < 0.0 { -n } else { n })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_faces_the_viewer_and_falls_back_on_zero() {
        let mut mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            indices: vec![[0, 1, 2]],
            normals: Some(vec![Vec3::Z, Vec3::X, Vec3::Z]),
            materials: vec![0],
            ..Default::default()
        };
        let n = shading_normal(&mesh, 0, 0.5, 0.0, Vec3::Z).unwrap();
        assert!((n - Vec3::new(1.0, 0.0, 1.0).normalize()).length() < 1e-6);
        let flipped = shading_normal(&mesh, 0, 0.5, 0.0, -Vec3::Z).unwrap();
        assert_eq!(flipped, -n);
        mesh.normals.as_mut().unwrap()[1] = Vec3::ZERO;
        assert_eq!(shading_normal(&mesh, 0, 0.5, 0.0, Vec3::Z), None);
    }
}

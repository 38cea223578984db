//! Applying an affine transform to a mesh: points by the matrix, normals by
//! its inverse transpose.

use crate::geometry::TriangleMesh;
use glam::{Mat3, Mat4};

pub fn transform_mesh(mesh: &mut TriangleMesh, transform: Mat4) {
    if transform == Mat4::IDENTITY {
        return;
    }
    for p in &mut mesh.positions {
        *p = transform.transform_point3(*p);
    }
    let normal_matrix = Mat3::from_mat4(transform).inverse().transpose();
    for n in mesh.normals.iter_mut().flatten() {
        *n = (normal_matrix * *n).normalize_or_zero();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn normals_stay_perpendicular_under_non_uniform_scale() {
        let mut mesh = TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::new(1.0, -1.0, 0.0), Vec3::Z],
            indices: vec![[0, 1, 2]],
            normals: Some(vec![Vec3::new(1.0, 1.0, 0.0).normalize(); 3]),
            texcoords: None,
            materials: vec![0],
        };
        transform_mesh(&mut mesh, Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)));
        let edge = mesh.positions[1] - mesh.positions[0];
        assert_eq!(edge, Vec3::new(2.0, -1.0, 0.0));
        let n = mesh.normals.unwrap()[0];
        assert!(n.dot(edge).abs() < 1e-6 && (n.length() - 1.0).abs() < 1e-6);
    }
}

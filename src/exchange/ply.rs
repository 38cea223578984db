//! A mesh as binary little-endian PLY, so every f32 coordinate survives:
//! `vertex` with `float x y z`, `face` with `list uchar uint
//! vertex_indices`, face `i` being primID `i`.

use crate::geometry::TriangleMesh;
use std::io::Write;

/// The PLY bytes of `mesh`, with `comment` lines in the header.
pub fn to_bytes(mesh: &TriangleMesh, comments: &[String]) -> Vec<u8> {
    let mut bytes = Vec::new();
    let _ = write!(bytes, "ply\nformat binary_little_endian 1.0\n");
    for comment in comments {
        let _ = writeln!(bytes, "comment {}", comment.replace(['\n', '\r'], " "));
    }
    let _ = write!(
        bytes,
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangle_count()
    );
    for p in &mesh.positions {
        for value in p.to_array() {
            bytes.extend(value.to_le_bytes());
        }
    }
    for triangle in &mesh.indices {
        bytes.push(3);
        for index in triangle {
            bytes.extend(index.to_le_bytes());
        }
    }
    bytes
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use std::path::Path;

    #[test]
    fn the_ply_loader_reads_back_every_bit() {
        let mesh = TriangleMesh::soup(&[
            [Vec3::new(0.1, 1e-30, -3.3e7), Vec3::X, Vec3::Y],
            [
                Vec3::ZERO,
                Vec3::new(f32::MIN_POSITIVE, 2.5, 1.0 / 3.0),
                Vec3::Z,
            ],
        ]);
        let bytes = to_bytes(&mesh, &["two\ntriangles".into()]);
        let back = crate::scene::formats::ply::parse(Path::new("m.ply"), &bytes).unwrap();
        let bits = |m: &TriangleMesh| -> Vec<[u32; 3]> {
            m.positions
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        assert_eq!(bits(&back), bits(&mesh));
        assert_eq!(back.indices, mesh.indices);
    }
}

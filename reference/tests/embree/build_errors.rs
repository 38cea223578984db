use raycheck_reference::{EmbreeError, SceneOptions, TriangleMeshRef};

use crate::{down_at, grid};

#[test]
fn an_index_past_the_vertices_is_refused_with_its_place() {
    let good = grid(1, 0.0);
    let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let indices = [[0, 1, 2], [2, 1, 3]];
    let bad = TriangleMeshRef {
        positions: &positions,
        indices: &indices,
    };
    let error = crate::device()
        .build_scene(&[good.as_ref(), bad], SceneOptions::default())
        .err()
        .expect("vertex 3 does not exist");
    assert!(
        matches!(
            error,
            EmbreeError::IndexOutOfRange {
                mesh: 1,
                triangle: 1,
                index: 3,
                vertex_count: 3
            }
        ),
        "{error}"
    );
}

#[test]
fn empty_scenes_and_empty_meshes_build_and_miss() {
    let device = crate::device();
    let empty = TriangleMeshRef {
        positions: &[],
        indices: &[],
    };
    for meshes in [vec![], vec![empty]] {
        let scene = device
            .build_scene(&meshes, SceneOptions::default())
            .unwrap();
        assert_eq!(scene.triangle_count(), 0);
        assert_eq!(scene.intersect(&down_at(0.5, 0.5)), None);
        assert!(!scene.occluded(&down_at(0.5, 0.5)));
    }
}

/// Embree drops a triangle with a NaN vertex at commit without an error;
/// the other triangles stay hittable.
#[test]
fn a_nan_vertex_drops_only_its_triangle() {
    let mut mesh = grid(2, 0.0);
    let last = mesh.positions.len() - 1;
    mesh.positions[last] = [f32::NAN, 2.0, 0.0];
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], SceneOptions::default())
        .unwrap();
    assert_eq!(scene.triangle_count(), 8);
    assert!(scene.intersect(&down_at(0.5, 0.5)).is_some());
    // Square (1, 1) upper triangle uses the NaN corner.
    assert_eq!(scene.intersect(&down_at(1.8, 1.8)), None);
}

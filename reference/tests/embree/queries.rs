use raycheck_reference::{RayQuery, SceneOptions};

use crate::{TestMesh, close, down_at, grid};

/// A tilted triangle as the second mesh's second triangle, behind a first
/// mesh it does not overlap, so the hit must name geom 1, prim 1.
fn tilted_scene() -> (Vec<TestMesh>, [[f32; 3]; 3]) {
    let p = [[1.0, -2.0, 0.5], [4.0, 1.0, -1.0], [0.5, 3.0, 2.0]];
    let far_away = TestMesh {
        positions: vec![
            [100.0, 100.0, 0.0],
            [101.0, 100.0, 0.0],
            [100.0, 101.0, 0.0],
        ],
        indices: vec![[0, 1, 2]],
    };
    let target = TestMesh {
        positions: vec![[50.0, 50.0, 50.0], p[0], p[1], p[2]],
        indices: vec![[0, 1, 2], [1, 2, 3]],
    };
    (vec![far_away, target], p)
}

#[test]
fn a_hit_reports_t_u_v_normal_and_ids_in_embree_convention() {
    let (meshes, p) = tilted_scene();
    let refs: Vec<_> = meshes.iter().map(TestMesh::as_ref).collect();
    let scene = crate::device()
        .build_scene(&refs, SceneOptions::default())
        .unwrap();

    let (u, v, t) = (0.3f64, 0.2f64, 7.5f64);
    let dir = [0.2f64, -0.3, -1.0];
    let point: Vec<f64> = (0..3)
        .map(|k| (1.0 - u - v) * p[0][k] as f64 + u * p[1][k] as f64 + v * p[2][k] as f64)
        .collect();
    let ray = RayQuery {
        origin: [0, 1, 2].map(|k| (point[k] - t * dir[k]) as f32),
        dir: dir.map(|d| d as f32),
        tnear: 0.0,
        tfar: f32::INFINITY,
    };
    let hit = scene
        .intersect(&ray)
        .expect("the ray is aimed inside the triangle");
    assert_eq!((hit.geom_id, hit.prim_id), (1, 1));
    assert!(close(hit.t, t as f32, 1e-5), "t = {}", hit.t);
    assert!(
        close(hit.u, u as f32, 1e-5) && close(hit.v, v as f32, 1e-5),
        "{hit:?}"
    );

    let e1: Vec<f32> = (0..3).map(|k| p[1][k] - p[0][k]).collect();
    let e2: Vec<f32> = (0..3).map(|k| p[2][k] - p[0][k]).collect();
    let normal = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    for k in 0..3 {
        assert!(
            close(hit.ng[k], normal[k], 1e-5),
            "Ng {:?} vs {normal:?}",
            hit.ng
        );
    }
}

#[test]
fn misses_and_segments_short_of_the_surface_find_nothing() {
    let mesh = grid(4, 0.0);
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], SceneOptions::default())
        .unwrap();
    let beside = down_at(5.5, 2.0);
    let short = RayQuery {
        tfar: 9.5,
        ..down_at(2.0, 2.0)
    };
    let behind = RayQuery {
        tnear: 10.5,
        ..down_at(2.0, 2.0)
    };
    for ray in [beside, short, behind] {
        assert_eq!(scene.intersect(&ray), None, "{ray:?}");
        assert!(!scene.occluded(&ray), "{ray:?}");
    }
}

#[test]
fn occlusion_agrees_with_the_closest_hit() {
    let mesh = grid(4, 0.0);
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], SceneOptions::default())
        .unwrap();
    let ray = down_at(1.3, 2.6);
    let hit = scene.intersect(&ray).expect("the grid lies below");
    assert!(close(hit.t, 10.0, 1e-6));
    assert!(scene.occluded(&ray));
    assert!(scene.occluded(&RayQuery { tfar: 10.5, ..ray }));
}

#[test]
fn queries_from_many_threads_match_one_thread() {
    let mesh = grid(16, 0.0);
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], SceneOptions::default())
        .unwrap();
    let rays: Vec<RayQuery> = (0..4096)
        .map(|i| down_at((i % 64) as f32 * 0.27 + 0.01, (i / 64) as f32 * 0.27 + 0.01))
        .collect();
    let serial: Vec<_> = rays.iter().map(|ray| scene.intersect(ray)).collect();
    assert!(serial.iter().filter(|hit| hit.is_some()).count() > 3000);
    let parallel: Vec<_> = std::thread::scope(|scope| {
        let workers: Vec<_> = rays
            .chunks(1024)
            .map(|chunk| {
                let scene = &scene;
                scope.spawn(move || {
                    raycheck_reference::enable_flush_to_zero_and_denormals_are_zero();
                    chunk
                        .iter()
                        .map(|ray| scene.intersect(ray))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap())
            .collect()
    });
    assert_eq!(serial, parallel);
}

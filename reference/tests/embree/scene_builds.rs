use raycheck_reference::{BuildQuality, Scene, SceneOptions};

use crate::{down_at, grid};

fn all_options() -> Vec<SceneOptions> {
    [BuildQuality::Low, BuildQuality::Medium, BuildQuality::High]
        .into_iter()
        .flat_map(|quality| [false, true].map(|robust| SceneOptions { quality, robust }))
        .collect()
}

#[test]
fn every_quality_with_and_without_robust_finds_the_same_triangles() {
    let n = 8;
    let mesh = grid(n, 0.0);
    let device = crate::device();
    for options in all_options() {
        let scene = device.build_scene(&[mesh.as_ref()], options).unwrap();
        assert_eq!(scene.triangle_count(), (2 * n * n) as usize);
        for i in 0..n {
            for j in 0..n {
                let square = 2 * (i * n + j);
                // Near the lower-left corner: the first triangle of the square.
                let lower = scene.intersect(&down_at(i as f32 + 0.2, j as f32 + 0.2));
                // Near the upper-right corner: the second one.
                let upper = scene.intersect(&down_at(i as f32 + 0.8, j as f32 + 0.8));
                assert_eq!(lower.map(|hit| hit.prim_id), Some(square), "{options:?}");
                assert_eq!(
                    upper.map(|hit| hit.prim_id),
                    Some(square + 1),
                    "{options:?}"
                );
            }
        }
    }
}

#[test]
fn robust_mode_finds_rays_through_shared_edges_and_vertices() {
    let n = 8;
    let mesh = grid(n, 0.0);
    let options = SceneOptions {
        quality: BuildQuality::Medium,
        robust: true,
    };
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], options)
        .unwrap();
    for i in 1..n {
        for j in 1..n {
            let (x, y) = (i as f32, j as f32);
            for (dx, dy) in [(0.0, 0.0), (0.5, 0.0), (0.0, 0.5), (0.5, -0.5)] {
                let ray = down_at(x + dx, y + dy);
                assert!(
                    scene.intersect(&ray).is_some(),
                    "leak at ({}, {})",
                    x + dx,
                    y + dy
                );
            }
        }
    }
}

#[test]
fn build_time_and_bytes_are_measured() {
    let device = crate::device();
    let small = grid(4, 0.0);
    let large = grid(64, 0.0);
    let build = |mesh: &crate::TestMesh| -> Scene {
        device
            .build_scene(&[mesh.as_ref()], SceneOptions::default())
            .unwrap()
    };
    let (small, large) = (build(&small), build(&large));
    assert!(large.build_time() > std::time::Duration::ZERO);
    assert!(small.bytes() > 0);
    // 8192 triangles need far more than 32 do.
    assert!(
        large.bytes() > 10 * small.bytes(),
        "{} vs {}",
        large.bytes(),
        small.bytes()
    );
}

#[test]
fn scenes_outlive_their_device_handle_and_cross_threads() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<Scene>();
    let mesh = grid(2, 0.0);
    let scene = crate::device()
        .build_scene(&[mesh.as_ref()], SceneOptions::default())
        .unwrap();
    let hit = std::thread::spawn(move || scene.intersect(&down_at(0.5, 0.5)))
        .join()
        .unwrap();
    assert!(hit.is_some());
}

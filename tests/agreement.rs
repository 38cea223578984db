//! Our BVHs against Embree (ROBUST, MEDIUM) on the compare ray sets:
//! no wrong answer on either side, and the agreement the foundation promises.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::check::{self, CompareSummary};
use raycheck::parallel::thread_pool;
use raycheck::scene;
use raycheck_reference::{BuildQuality, Device, DeviceConfig, SceneOptions};

/// Primary rays per side: enough rays to meet every triangle of the small
/// scenes many times, few enough to keep the suite fast.
const RESOLUTION: u32 = 192;

fn compare_scene(name: &str, options: BuildOptions) -> CompareSummary {
    let scene = scene::load(name).unwrap();
    let pool = thread_pool(None).unwrap();
    let device = Device::new(&DeviceConfig {
        threads: Some(pool.current_num_threads()),
        verbose: 0,
    })
    .unwrap();
    let robust = SceneOptions {
        quality: BuildQuality::Medium,
        robust: true,
    };
    let reference = check::embree::build_scene(&device, &scene.mesh, robust).unwrap();
    let bvh = Bvh::build(&scene.mesh, &options);
    pool.install(|| check::compare(&scene, &bvh, &reference, RESOLUTION))
}

fn assert_agrees(summary: &CompareSummary) {
    let context = serde_json::to_string_pretty(summary).unwrap();
    assert!(
        summary.rays > RESOLUTION as u64 * RESOLUTION as u64,
        "{context}"
    );
    assert_eq!(summary.ours_wrong, 0, "{context}");
    assert_eq!(summary.embree_wrong, 0, "{context}");
    assert!(summary.hit_agreement >= 0.99999, "{context}");
    assert!(summary.prim_agreement >= 0.9999, "{context}");
    assert_eq!(summary.ours_t_off, 0, "{context}");
    // Embree's robust test translates the vertices to the ray origin before
    // computing the normal, so on secondary rays that meet a triangle far
    // closer than its vertices its `t` can be off in the fifth digit (the
    // referee counts those in `embree_t_off`); primary rays stay tight.
    assert!(summary.max_rel_t_error_primary <= 1e-5, "{context}");
}

#[test]
fn cornell_agrees_with_embree() {
    assert_agrees(&compare_scene("cornell", BuildOptions::sah()));
    assert_agrees(&compare_scene("cornell", BuildOptions::median()));
}

#[test]
fn monkey_agrees_with_embree() {
    assert_agrees(&compare_scene("monkey", BuildOptions::sah()));
    assert_agrees(&compare_scene("monkey", BuildOptions::median()));
}

#[test]
fn dragon_11k_agrees_with_embree() {
    assert_agrees(&compare_scene("dragon-11k", BuildOptions::sah()));
    assert_agrees(&compare_scene("dragon-11k", BuildOptions::median()));
}

#[test]
fn dragon_48k_agrees_with_embree() {
    assert_agrees(&compare_scene("dragon-48k", BuildOptions::sah()));
    assert_agrees(&compare_scene("dragon-48k", BuildOptions::median()));
}

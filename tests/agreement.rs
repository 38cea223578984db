//! Our BVHs against Embree (ROBUST, MEDIUM) on the compare ray sets:
//! no wrong answer on either side, and the agreement the foundation promises.

use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::check::{self, CompareSummary};
use raycheck::geometry::{Hit, Ray};
use raycheck::parallel::thread_pool;
use raycheck::scene;
use raycheck::trace::Intersector;

/// Primary rays per side: enough rays to meet every triangle of the small
/// scenes many times, few enough to keep the suite fast.
const RESOLUTION: u32 = 192;

fn compare_scene(name: &str, options: BuildOptions) -> CompareSummary {
    let scene = scene::load(name).unwrap();
    let pool = thread_pool(None).unwrap();
    let device = crate::support::embree_device(pool.current_num_threads());
    let reference = crate::support::reference_scene(&device, &scene.mesh);
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

/// Our BVH with faults planted on a fixed subset of rays: a dropped hit, a
/// hit moved along the ray, and a false occlusion.
struct Faulty(Bvh);

impl Faulty {
    /// Picks about one ray in `period` by its bits, the same on any thread.
    fn picks(ray: &Ray, period: u32, salt: u32) -> bool {
        let h = ray.dir.x.to_bits() ^ ray.dir.y.to_bits().rotate_left(11) ^ salt;
        h.wrapping_mul(0x9E37_79B9) >> 16 & 0xFFFF < 0x10000 / period
    }
}

impl Intersector for Faulty {
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let hit = self.0.intersect(ray)?;
        if Self::picks(ray, 200, 1) {
            return None;
        }
        if Self::picks(ray, 200, 2) {
            return Some(Hit {
                t: hit.t * 1.001,
                ..hit
            });
        }
        Some(hit)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.0.occluded(ray) || Self::picks(ray, 200, 3)
    }
}

#[test]
fn the_check_catches_planted_faults() {
    let scene = scene::load("monkey").unwrap();
    let device = crate::support::embree_device(2);
    let reference = crate::support::reference_scene(&device, &scene.mesh);
    let faulty = Faulty(Bvh::build(&scene.mesh, &BuildOptions::sah()));
    let summary = thread_pool(None)
        .unwrap()
        .install(|| check::compare(&scene, &faulty, &reference, 96));
    let context = serde_json::to_string_pretty(&summary).unwrap();
    assert!(summary.hit_mismatch > 0, "{context}");
    assert!(summary.occlusion_mismatch > 0, "{context}");
    assert!(summary.ours_t_off > 0, "{context}");
    // Every planted fault is ours; none may be blamed on Embree.
    assert!(summary.ours_wrong > 0, "{context}");
    assert_eq!(summary.embree_wrong, 0, "{context}");
    assert_eq!(summary.embree_t_off, 0, "{context}");
}

//! Our BVHs against Embree (ROBUST, MEDIUM) on the compare ray sets:
//! no wrong answer on either side, and the agreement the foundation promises.

use crate::support::{compare, compare_with, reference_scene, workers};
use raycheck::backends::{Answers, Backend};
use raycheck::bvh::{BuildOptions, Bvh};
use raycheck::geometry::{Hit, Ray};
use raycheck::results::CompareSummary;
use raycheck::scene;
use raycheck::trace::Intersector;
use std::time::Duration;

/// Primary rays per side: enough rays to meet every triangle of the small
/// scenes many times, few enough to keep the suite fast.
const RESOLUTION: u32 = 192;

/// Our three builders and Embree robust, on one scene.
fn compare_builders(name: &str) -> CompareSummary {
    compare(name, "ours,ours-sah,ours-median,embree-robust", RESOLUTION)
}

fn assert_agrees(summary: &CompareSummary) {
    let context = serde_json::to_string_pretty(summary).unwrap();
    assert!(
        summary.rays() > RESOLUTION as u64 * RESOLUTION as u64,
        "{context}"
    );
    for backend in &summary.verdicts.backends {
        assert_eq!(backend.wrong, 0, "{}: {context}", backend.name);
        assert_eq!(backend.nan_outputs, 0, "{}: {context}", backend.name);
    }
    for ours in ["ours", "ours-sah", "ours-median"] {
        assert_eq!(
            summary.verdicts.backend(ours).unwrap().t_off,
            0,
            "{context}"
        );
    }
    for d in &summary.against_first {
        assert!(d.hit_agreement >= 0.99999, "{}: {context}", d.backend);
        assert!(d.prim_agreement >= 0.9999, "{}: {context}", d.backend);
        // Embree's robust test translates the vertices to the ray origin
        // before computing the normal, so on secondary rays that meet a
        // triangle far closer than its vertices its `t` can be off in the
        // fifth digit (the referee counts those in `t off`); primary rays
        // stay tight.
        assert!(
            d.max_rel_t_error_primary <= 1e-5,
            "{}: {context}",
            d.backend
        );
    }
}

#[test]
fn cornell_agrees_with_embree() {
    assert_agrees(&compare_builders("cornell"));
}

#[test]
fn monkey_agrees_with_embree() {
    assert_agrees(&compare_builders("monkey"));
}

#[test]
fn dragon_11k_agrees_with_embree() {
    assert_agrees(&compare_builders("dragon-11k"));
}

#[test]
fn dragon_48k_agrees_with_embree() {
    assert_agrees(&compare_builders("dragon-48k"));
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

impl Backend for Faulty {
    fn name(&self) -> String {
        "faulty".into()
    }
    fn answers(&self) -> Answers {
        Answers::ALL
    }
    fn build_time(&self) -> Duration {
        Duration::ZERO
    }
    fn bytes(&self) -> Option<usize> {
        None
    }
}

#[test]
fn the_check_catches_planted_faults() {
    let scene = scene::load("monkey").unwrap();
    let workers = workers(Some(2));
    let reference = reference_scene(workers.device(), &scene.mesh);
    let faulty = Faulty(Bvh::build(&scene.mesh, &BuildOptions::sah()));
    let summary = compare_with(&scene, &[&faulty, &reference], 96);
    let context = serde_json::to_string_pretty(&summary).unwrap();
    let against = &summary.against_first[0];
    assert!(against.hit_mismatch > 0, "{context}");
    assert!(against.occlusion_mismatch > 0, "{context}");
    let faulty = summary.verdicts.backend("faulty").unwrap();
    assert!(faulty.t_off > 0, "{context}");
    assert!(faulty.wrong > 0, "{context}");
    // Every planted fault is the faulty backend's; none may be blamed on
    // Embree.
    let embree = summary.verdicts.backend("embree-robust").unwrap();
    assert_eq!((embree.wrong, embree.t_off), (0, 0), "{context}");
    // Each kind of fault has a replayable sample naming the culprit.
    assert!(summary.samples.iter().any(|s| {
        s.answers[0].judgement == raycheck::check::Judgement::Wrong
            && s.answers[1].judgement.is_admissible()
    }));
}

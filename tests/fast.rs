//! The fast BVH (`bvh::wide`) against Embree (ROBUST, MEDIUM) on the compare
//! ray sets, and `raycheck perf`'s JSON.

use raycheck::bvh::wide::WideBvh;
use raycheck::check::{self, CompareSummary};
use raycheck::parallel::thread_pool;
use raycheck::perf::{self, PerfOptions};
use raycheck::scene;

const RESOLUTION: u32 = 192;

fn compare_scene(name: &str) -> CompareSummary {
    let scene = scene::load(name).unwrap();
    let pool = thread_pool(None).unwrap();
    let device = crate::support::embree_device(pool.current_num_threads());
    let reference = crate::support::reference_scene(&device, &scene.mesh);
    let bvh = pool.install(|| WideBvh::build(&scene.mesh));
    bvh.validate(&scene.mesh).unwrap();
    pool.install(|| check::compare(&scene, &bvh, &reference, RESOLUTION))
}

#[test]
fn fast_bvh_is_never_wrong_against_embree() {
    for name in ["cornell", "monkey", "dragon-11k", "dragon-48k"] {
        let summary = compare_scene(name);
        let context = serde_json::to_string_pretty(&summary).unwrap();
        assert!(
            summary.rays > RESOLUTION as u64 * RESOLUTION as u64,
            "{context}"
        );
        assert_eq!(summary.ours_wrong, 0, "{context}");
        assert_eq!(summary.ours_t_off, 0, "{context}");
        assert!(summary.hit_agreement >= 0.99999, "{context}");
    }
}

#[test]
fn fast_bvh_is_never_wrong_against_embree_on_the_large_dragons() {
    for name in ["dragon-203k", "dragon-871k"] {
        let summary = compare_scene(name);
        let context = serde_json::to_string_pretty(&summary).unwrap();
        assert_eq!(summary.ours_wrong, 0, "{context}");
        assert_eq!(summary.ours_t_off, 0, "{context}");
    }
}

#[test]
fn perf_json_has_every_field_for_every_scene() {
    let report = perf::run(
        &PerfOptions {
            quick: true,
            threads: Some(1),
        },
        &|_| {},
    )
    .unwrap();
    let json = serde_json::to_value(&report).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), raycheck::scene::QUICK_SCENES.len() * 2);
    for row in rows {
        for key in [
            "build_ms",
            "embree_build_ms",
            "mrays_primary",
            "embree_mrays_primary",
            "mrays_shadow",
            "embree_mrays_shadow",
            "mrays_diffuse",
            "embree_mrays_diffuse",
            "bytes_per_tri",
            "embree_bytes_per_tri",
        ] {
            let value = row[key].as_f64().unwrap_or(f64::NAN);
            assert!(value.is_finite() && value > 0.0, "{key} in {row}");
        }
        assert_eq!(row["threads"], 1, "{row}");
    }
    assert_eq!(report.scaling.len(), 2);
    assert!(report.markdown().contains("dragon-11k"));
}

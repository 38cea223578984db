//! The quick stability catalogue on the cases where our tracer is already
//! exact: no wrong answer of ours, no panic, no NaN out, no self-hit, and
//! the BVH equal to the loop over all triangles. (The leak, grid, sliver,
//! scale and long-ray cases are not here yet: see the README.)

use raycheck::parallel::thread_pool;
use raycheck::stability::{CaseResult, Context, run_catalogue};
use raycheck_reference::{Device, DeviceConfig};

fn quick(filter: &str) -> Vec<CaseResult> {
    let pool = thread_pool(None).unwrap();
    let device = Device::new(&DeviceConfig {
        threads: Some(pool.current_num_threads()),
        verbose: 0,
    })
    .unwrap();
    let context = Context {
        device: &device,
        quick: true,
    };
    pool.install(|| run_catalogue(&context, Some(filter)))
}

#[test]
fn exact_cases_have_no_wrong_answer_of_ours() {
    for filter in [
        "flat_boxes",
        "grazing",
        "degenerate",
        "tnear_tfar",
        "nan_and_inf",
        "self_intersection",
        "ties",
    ] {
        let results = quick(filter);
        assert_eq!(results.len(), 1, "{filter}");
        let r = &results[0];
        let context = serde_json::to_string_pretty(r).unwrap();
        assert!(r.rays > 0, "{context}");
        assert_eq!((r.ours_wrong, r.panics), (0, 0), "{context}");
        assert_eq!(r.self_hits.unwrap_or(0), 0, "{context}");
        assert_eq!(r.traversal_mismatches.unwrap_or(0), 0, "{context}");
    }
}

#[test]
fn invalid_rays_and_vertices_give_no_nan() {
    let r = &quick("nan_and_inf")[0];
    assert_eq!(r.nan_outputs, 0, "{r:?}");
}

//! The whole quick stability catalogue: no wrong answer of ours, no panic,
//! no NaN out of our tracer, no self-hit, no leak from inside a closed
//! mesh, and the BVH equal to the loop over all triangles.

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
fn no_case_has_a_wrong_answer_of_ours() {
    let results = quick("");
    assert_eq!(results.len(), 14);
    for r in &results {
        let context = serde_json::to_string_pretty(r).unwrap();
        assert!(r.rays > 0, "{context}");
        assert_eq!((r.ours_wrong, r.panics), (0, 0), "{context}");
        assert_eq!(r.nan_outputs.ours, 0, "{context}");
        assert_eq!(r.self_hits.unwrap_or(0), 0, "{context}");
        assert_eq!(r.traversal_mismatches.unwrap_or(0), 0, "{context}");
    }
    // Every ray of case 1 starts inside a closed sphere: none may leak.
    let leaks = results[0].leaks.expect("case 1 counts leaks");
    assert_eq!(results[0].name, "closed_mesh_leaks");
    assert_eq!(leaks.ours, 0, "{leaks:?}");
}

/// Case 8 spawns its rays per scale: where f32 collapses the triangles of a
/// placement, the other translations of that scale make up the shortfall,
/// so every scale gets at least the rays asked for, with no self-hit.
#[test]
fn every_scale_of_case_8_spawns_the_rays_asked_for() {
    use raycheck::stability::scale::{SCALES, TRANSLATIONS, spawn_at_scale};
    let wanted = 2_400;
    for scale in SCALES {
        let spawned = spawn_at_scale(scale, wanted);
        assert_eq!(spawned.len(), TRANSLATIONS.len());
        let rays: u64 = spawned.iter().map(|s| s.rays).sum();
        let self_hits: u64 = spawned.iter().map(|s| s.self_hits).sum();
        assert!(rays >= wanted as u64, "scale {scale}: {spawned:?}");
        assert_eq!(self_hits, 0, "scale {scale}: {spawned:?}");
    }
}

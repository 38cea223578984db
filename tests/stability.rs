//! The whole quick stability catalogue: no wrong answer of ours, no panic,
//! no NaN out of our tracer, no self-hit, no leak from inside a closed
//! mesh, and the BVH equal to the loop over all triangles.

use raycheck::backends::BackendName;
use raycheck::run::Form;
use raycheck::stability::{self, CaseResult};

fn quick(filter: &str) -> Vec<CaseResult> {
    let run = crate::support::run(Form::Quick);
    stability::run(&run, &BackendName::defaults(), Some(filter))
}

#[test]
fn no_case_has_a_wrong_answer_of_ours() {
    let results = quick("");
    assert_eq!(results.len(), 14);
    for r in &results {
        let context = serde_json::to_string_pretty(r).unwrap();
        assert!(r.rays > 0 && r.verdicts.judged > 0, "{context}");
        let ours = r.verdicts.backend("ours").expect("ours is checked");
        assert_eq!((ours.wrong, ours.t_off, r.panics), (0, 0, 0), "{context}");
        assert_eq!(ours.nan_outputs, 0, "{context}");
        assert_eq!(r.self_hits.unwrap_or(0), 0, "{context}");
        assert_eq!(r.traversal_mismatches.unwrap_or(0), 0, "{context}");
    }
    // Every ray of case 1 starts inside a closed sphere: none may leak.
    assert_eq!(results[0].name, "closed_mesh_leaks");
    assert_eq!(results[0].leaks(0), Some(0), "{:?}", results[0].verdicts);
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

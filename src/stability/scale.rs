//! Case 8: scale and offset. The leak, grazing and self-intersection cases
//! at scales 1e-6 … 1e6 and translations 0, 1e3, 1e5, 1e7.

use super::grazing::grazing_trial;
use super::harness::Tally;
use super::leaks::leak_trial;
use super::self_intersection::{Spawn, spawn_trial};
use super::shapes::{Placement, icosphere};
use super::{CaseResult, Context};
use glam::DVec3;

pub const SCALES: [f64; 5] = [1e-6, 1e-3, 1.0, 1e3, 1e6];
pub const TRANSLATIONS: [f64; 4] = [0.0, 1e3, 1e5, 1e7];

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut total = Tally::default();
    let mut self_hits = 0;
    let mut details = Vec::new();
    for scale in SCALES {
        for translation in TRANSLATIONS {
            let placement = Placement {
                scale,
                offset: DVec3::splat(translation),
            };
            let leaks = leak_trial(
                context,
                &icosphere(3, placement),
                placement,
                context.rays(20_000, 200),
                8,
            )?;
            let (grazing, _) = grazing_trial(context, placement, context.rays(1_000, 30))?;
            let spawned = spawn_trial(placement, Spawn::Offset, context.rays(25_000, 300), 8);
            self_hits += spawned.self_hits;
            details.push(serde_json::json!({
                "scale": scale, "translation": translation,
                "leak_rays": leaks.rays, "leaks": leaks.misses,
                "grazing_ours_wrong": grazing.ours_wrong, "grazing_embree_wrong": grazing.embree_wrong,
                "grazing_embree_robust_wrong": grazing.embree_robust_wrong,
                "spawn": spawned,
            }));
            total += leaks;
            // Grazing rays may miss the plane: their misses are no leaks.
            total += Tally {
                misses: Default::default(),
                ..grazing
            };
            total.rays += spawned.rays;
        }
    }
    let mut result = CaseResult::from_tally("scale_and_offset", &total);
    result.leaks = Some(total.misses);
    result.self_hits = Some(self_hits);
    result.details = serde_json::Value::Array(details);
    Ok(result)
}

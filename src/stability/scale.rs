//! Case 8: scale and offset. The leak, grazing and self-intersection cases
//! at scales 1e-6 … 1e6 and translations 0, 1e3, 1e5, 1e7.

use super::grazing::grazing_trial;
use super::leaks::leak_trial;
use super::self_intersection::{Spawn, SpawnStats, spawn_trial};
use super::shapes::{Placement, icosphere};
use super::{CaseDetails, CaseResult, Context};
use crate::results::Verdicts;
use glam::DVec3;
use serde::Serialize;

pub const SCALES: [f64; 5] = [1e-6, 1e-3, 1.0, 1e3, 1e6];
pub const TRANSLATIONS: [f64; 4] = [0.0, 1e3, 1e5, 1e7];

/// Rays spawned with our offset at each scale, summed over its translations.
pub fn spawn_rays_per_scale(context: &Context) -> usize {
    context.rays(1_000_000, 2_400)
}

fn placement(scale: f64, translation: f64) -> Placement {
    Placement {
        scale,
        offset: DVec3::splat(translation),
    }
}

/// Spawns at least `rays` rays with our offset at one scale, in the order of
/// `TRANSLATIONS` reversed. Where f32 collapses every triangle (scale 1e-6
/// at 1e3 and beyond) a placement yields fewer rays than asked, and the
/// translations after it make up the shortfall; translation 0 comes last
/// and can represent every scale. Returned in the order of `TRANSLATIONS`.
pub fn spawn_at_scale(scale: f64, rays: usize) -> Vec<SpawnStats> {
    let mut still_wanted = rays.div_ceil(2);
    let mut spawned: Vec<SpawnStats> = TRANSLATIONS
        .iter()
        .rev()
        .enumerate()
        .map(|(i, &translation)| {
            let share = still_wanted.div_ceil(TRANSLATIONS.len() - i);
            let stats = spawn_trial(placement(scale, translation), Spawn::Offset, share, 8);
            still_wanted -= (stats.rays as usize / 2).min(still_wanted);
            stats
        })
        .collect();
    spawned.reverse();
    spawned
}

/// What one placement showed: leaks from inside an icosphere, grazing rays
/// on a plane, and rays spawned with our offset.
#[derive(Clone, Debug, Serialize)]
pub struct PlacementResult {
    pub scale: f64,
    pub translation: f64,
    /// Rays from inside the icosphere, with each backend's leaks.
    pub leaks: Verdicts,
    /// Grazing rays on the plane (their misses are no leaks).
    pub grazing: Verdicts,
    pub spawn: SpawnStats,
}

pub fn run(context: &Context) -> anyhow::Result<CaseResult> {
    let mut total = Verdicts::default();
    let mut spawned_rays = 0;
    let mut self_hits = 0;
    let mut placements = Vec::new();
    for scale in SCALES {
        let spawns = spawn_at_scale(scale, spawn_rays_per_scale(context));
        for (translation, spawned) in TRANSLATIONS.into_iter().zip(spawns) {
            let placement = placement(scale, translation);
            let leak_verdicts = leak_trial(
                context,
                &icosphere(3, placement),
                placement,
                context.rays(20_000, 200),
                8,
            )?;
            let (grazing, _) = grazing_trial(context, placement, context.rays(1_000, 30))?;
            self_hits += spawned.self_hits;
            spawned_rays += spawned.rays;
            total += &leak_verdicts;
            total += &grazing;
            placements.push(PlacementResult {
                scale,
                translation,
                leaks: leak_verdicts,
                grazing,
                spawn: spawned,
            });
        }
    }
    let mut result = CaseResult::judged("scale_and_offset", total).with_leaks();
    result.rays += spawned_rays;
    result.self_hits = Some(self_hits);
    result.details = CaseDetails::Placements { placements };
    Ok(result)
}

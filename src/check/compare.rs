//! `raycheck compare`: the ray sets of a scene traced through both backends,
//! every difference judged.
//!
//! The rays: one primary ray through each pixel centre of an N×N view from
//! the scene's camera; from each primary hit, a shadow ray to every light
//! and a mirror-reflection ray (whatever the material, to exercise secondary
//! rays everywhere). Secondary rays are spawned from our hit, so both
//! backends see the very same rays.

use super::checked::{CheckLog, Checked, Finding, VerdictCounts};
use super::difference::{Difference, DifferenceKind};
use super::referee::Verdict;
use crate::geometry::{Hit, Ray};

use crate::render::surface::SurfacePoint;
use crate::scene::Scene;
use crate::trace::Intersector;
use rayon::prelude::*;
use serde::Serialize;

/// How many disagreeing rays the summary keeps, bit-exact, for replay.
pub const SAMPLE_LIMIT: usize = 64;

/// The outcome of one compare run; the JSON of `raycheck compare --json`.
#[derive(Clone, Debug, Serialize)]
pub struct CompareSummary {
    pub scene: String,
    pub triangles: usize,
    pub resolution: u32,
    pub rays: u64,
    pub primary_rays: u64,
    pub shadow_rays: u64,
    pub reflection_rays: u64,
    /// Closest-hit queries where one backend hit and the other missed.
    pub hit_mismatch: u64,
    /// Closest-hit queries where both hit, but different triangles.
    pub prim_mismatch: u64,
    /// Same triangle, `t` differing beyond the tolerance.
    pub t_mismatch: u64,
    /// Any-hit queries with different answers.
    pub occlusion_mismatch: u64,
    /// Largest relative `t` difference where both hit the same triangle.
    pub max_rel_t_error: f32,
    /// The same, over primary rays only.
    pub max_rel_t_error_primary: f32,
    /// Largest `|Δu|`, `|Δv|` where both hit the same triangle.
    pub max_uv_error: f32,
    /// Hit/miss, triangle or occlusion decisions the referee found wrong.
    pub ours_wrong: u64,
    pub embree_wrong: u64,
    /// Differences where both answers are valid (ties, edges within f32
    /// precision), distance differences included.
    pub ambiguous: u64,
    /// Same triangle, but `t` further than the tolerance from the exact value.
    pub ours_t_off: u64,
    pub embree_t_off: u64,
    /// Fraction of all queries whose hit/miss (or occluded) answers agree.
    pub hit_agreement: f64,
    /// Fraction of closest-hit queries that agree on the triangle, counting
    /// referee-certified ties as agreement.
    pub prim_agreement: f64,
    /// Up to [`SAMPLE_LIMIT`] disagreements, wrong answers first.
    pub samples: Vec<DisagreementRecord>,
}

/// One disagreement, with every float also given as its bit pattern.
#[derive(Clone, Debug, Serialize)]
pub struct DisagreementRecord {
    pub ray_set: RaySet,
    pub query: &'static str,
    pub verdict: &'static str,
    pub ray: RayRecord,
    pub ours: AnswerRecord,
    pub embree: AnswerRecord,
}

/// A ray as decimals (shortest round-trip) and as hex f32 bits.
#[derive(Clone, Debug, Serialize)]
pub struct RayRecord {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub tnear: f32,
    pub tfar: f32,
    /// origin xyz, dir xyz, tnear, tfar as `0x...` f32 bit patterns.
    pub bits: [String; 8],
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "answer", rename_all = "snake_case")]
pub enum AnswerRecord {
    Hit { prim: u32, t: f32, u: f32, v: f32 },
    Miss,
    Occluded { occluded: bool },
}

/// The ray sets `compare` traces, each checked and reported on its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RaySet {
    Primary,
    Shadow,
    Reflection,
}

/// Traces the compare ray sets of `scene` through `ours` and `embree`.
pub fn compare<A, B>(scene: &Scene, ours: &A, embree: &B, resolution: u32) -> CompareSummary
where
    A: Intersector + ?Sized,
    B: Intersector + ?Sized,
{
    let primary = Checked::new(ours, embree);
    let shadow = Checked::new(ours, embree);
    let reflection = Checked::new(ours, embree);
    (0..resolution).into_par_iter().for_each(|y| {
        for x in 0..resolution {
            let ray = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, resolution, resolution);
            let Some(hit) = primary.intersect(&ray) else {
                continue;
            };
            let surface = SurfacePoint::new(&scene.mesh, &ray, &hit);
            for light in &scene.lights {
                shadow.occluded(&surface.shadow_ray(light.representative_point()));
            }
            reflection.intersect(&surface.reflection_ray());
        }
    });
    summarize(
        scene,
        resolution,
        [
            (RaySet::Primary, primary.into_log()),
            (RaySet::Shadow, shadow.into_log()),
            (RaySet::Reflection, reflection.into_log()),
        ],
    )
}

fn summarize(scene: &Scene, resolution: u32, logs: [(RaySet, CheckLog); 3]) -> CompareSummary {
    let [primary, shadow, reflection] = &logs;
    let mut sets = Vec::new();
    let mut differences = Vec::new();
    let mut verdicts = Vec::new();
    for (set, log) in &logs {
        verdicts.extend(log.judge(&scene.mesh));
        differences.extend_from_slice(&log.differences);
        sets.extend(std::iter::repeat_n(*set, log.differences.len()));
    }
    let counts_by_verdict = VerdictCounts::tally(&differences, &verdicts);
    let kinds: Vec<DifferenceKind> = differences.iter().map(Difference::kind).collect();
    let count_kind = |kind: DifferenceKind| kinds.iter().filter(|&&k| k == kind).count() as u64;
    let hit_mismatch = count_kind(DifferenceKind::HitMiss);
    let prim_mismatch = count_kind(DifferenceKind::Prim);
    let t_mismatch = count_kind(DifferenceKind::Distance);
    let occlusion_mismatch = count_kind(DifferenceKind::Occlusion);
    let certified_ties = kinds
        .iter()
        .zip(&verdicts)
        .filter(|&(&k, &v)| k == DifferenceKind::Prim && v == Verdict::Ambiguous)
        .count() as u64;
    let intersect_queries: u64 = logs.iter().map(|(_, l)| l.intersect_queries).sum();
    let rays = intersect_queries + logs.iter().map(|(_, l)| l.occluded_queries).sum::<u64>();
    let fraction = |bad: u64, all: u64| {
        if all == 0 {
            1.0
        } else {
            1.0 - bad as f64 / all as f64
        }
    };
    let max_of = |f: fn(&CheckLog) -> f32| logs.iter().map(|(_, l)| f(l)).fold(0.0, f32::max);
    CompareSummary {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        resolution,
        rays,
        primary_rays: primary.1.intersect_queries,
        shadow_rays: shadow.1.occluded_queries,
        reflection_rays: reflection.1.intersect_queries,
        hit_mismatch,
        prim_mismatch,
        t_mismatch,
        occlusion_mismatch,
        max_rel_t_error: max_of(|l| l.max_rel_t_error),
        max_rel_t_error_primary: primary.1.max_rel_t_error,
        max_uv_error: max_of(|l| l.max_uv_error),
        ours_wrong: counts_by_verdict.ours_wrong,
        embree_wrong: counts_by_verdict.embree_wrong,
        ambiguous: counts_by_verdict.ambiguous,
        ours_t_off: counts_by_verdict.ours_t_off,
        embree_t_off: counts_by_verdict.embree_t_off,
        hit_agreement: fraction(hit_mismatch + occlusion_mismatch, rays),
        prim_agreement: fraction(prim_mismatch - certified_ties, intersect_queries),
        samples: samples(&sets, &differences, &verdicts),
    }
}

fn samples(
    sets: &[RaySet],
    differences: &[Difference],
    verdicts: &[Verdict],
) -> Vec<DisagreementRecord> {
    let mut order: Vec<usize> = (0..differences.len()).collect();
    order.sort_by_key(|&i| (verdicts[i], sets[i]));
    order
        .into_iter()
        .take(SAMPLE_LIMIT)
        .map(|i| record(sets[i], &differences[i], verdicts[i]))
        .collect()
}

fn record(set: RaySet, difference: &Difference, verdict: Verdict) -> DisagreementRecord {
    let hit_record = |h: &Option<Hit>| match h {
        Some(h) => AnswerRecord::Hit {
            prim: h.prim,
            t: h.t,
            u: h.u,
            v: h.v,
        },
        None => AnswerRecord::Miss,
    };
    let (query, ours, embree) = match difference {
        Difference::Intersect {
            ours, reference, ..
        } => ("intersect", hit_record(ours), hit_record(reference)),
        Difference::Occluded {
            ours, reference, ..
        } => (
            "occluded",
            AnswerRecord::Occluded { occluded: *ours },
            AnswerRecord::Occluded {
                occluded: *reference,
            },
        ),
    };
    DisagreementRecord {
        ray_set: set,
        query,
        verdict: Finding::of(difference, verdict).name(),
        ray: ray_record(difference.ray()),
        ours,
        embree,
    }
}

fn ray_record(ray: &Ray) -> RayRecord {
    RayRecord {
        origin: ray.origin.to_array(),
        dir: ray.dir.to_array(),
        tnear: ray.tnear,
        tfar: ray.tfar,
        bits: ray.inputs().map(|v| format!("{:#010x}", v.to_bits())),
    }
}

//! `raycheck compare`: the ray sets of a scene traced through both backends,
//! every difference judged.
//!
//! The rays: one primary ray through each pixel centre of an N×N view from
//! the scene's camera; from each primary hit, a shadow ray to every light
//! and a mirror-reflection ray (whatever the material, to exercise secondary
//! rays everywhere). Secondary rays are spawned from our hit, so both
//! backends see the very same rays.

use super::checked::{CheckLog, Checked, VerdictCounts};
use super::difference::{Difference, DifferenceKind};
use super::referee::Verdict;
use crate::geometry::{Hit, Ray};
use crate::render::surface::SurfacePoint;
use crate::scene::Scene;
use crate::trace::Intersector;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};

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

/// Traces the compare ray sets of `scene` through `ours` and `embree`.
pub fn compare<A, B>(scene: &Scene, ours: &A, embree: &B, resolution: u32) -> CompareSummary
where
    A: Intersector + ?Sized,
    B: Intersector + ?Sized,
{
    let primary = Checked::new(ours, embree);
    let secondary = Checked::new(ours, embree);
    let counts = RayCounts::default();
    (0..resolution).into_par_iter().for_each(|y| {
        for x in 0..resolution {
            let ray = scene
                .camera
                .ray(x as f32 + 0.5, y as f32 + 0.5, resolution, resolution);
            counts.primary.fetch_add(1, Ordering::Relaxed);
            if let Some(hit) = primary.intersect(&ray) {
                trace_secondary(scene, &secondary, &ray, &hit, &counts);
            }
        }
    });
    let primary = primary.into_log();
    let max_rel_t_error_primary = primary.max_rel_t_error;
    let log = primary.merge(secondary.into_log());
    let mut summary = summarize(scene, resolution, log, &counts);
    summary.max_rel_t_error_primary = max_rel_t_error_primary;
    summary
}

#[derive(Default)]
struct RayCounts {
    primary: AtomicU64,
    shadow: AtomicU64,
    reflection: AtomicU64,
}

fn trace_secondary<I: Intersector + ?Sized>(
    scene: &Scene,
    checked: &I,
    ray: &Ray,
    hit: &Hit,
    counts: &RayCounts,
) {
    let surface = SurfacePoint::new(&scene.mesh, ray, hit);
    for light in &scene.lights {
        checked.occluded(&surface.shadow_ray(light.representative_point()));
        counts.shadow.fetch_add(1, Ordering::Relaxed);
    }
    checked.intersect(&surface.reflection_ray());
    counts.reflection.fetch_add(1, Ordering::Relaxed);
}

fn summarize(scene: &Scene, resolution: u32, log: CheckLog, counts: &RayCounts) -> CompareSummary {
    let verdicts = log.judge(&scene.mesh);
    let counts_by_verdict = VerdictCounts::tally(&log.differences, &verdicts);
    let kinds: Vec<DifferenceKind> = log.differences.iter().map(Difference::kind).collect();
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
    let rays = log.intersect_queries + log.occluded_queries;
    let fraction = |bad: u64, all: u64| {
        if all == 0 {
            1.0
        } else {
            1.0 - bad as f64 / all as f64
        }
    };
    CompareSummary {
        scene: scene.name.clone(),
        triangles: scene.mesh.triangle_count(),
        resolution,
        rays,
        primary_rays: counts.primary.load(Ordering::Relaxed),
        shadow_rays: counts.shadow.load(Ordering::Relaxed),
        reflection_rays: counts.reflection.load(Ordering::Relaxed),
        hit_mismatch,
        prim_mismatch,
        t_mismatch,
        occlusion_mismatch,
        max_rel_t_error: log.max_rel_t_error,
        max_rel_t_error_primary: log.max_rel_t_error,
        max_uv_error: log.max_uv_error,
        ours_wrong: counts_by_verdict.ours_wrong,
        embree_wrong: counts_by_verdict.embree_wrong,
        ambiguous: counts_by_verdict.ambiguous,
        ours_t_off: counts_by_verdict.ours_t_off,
        embree_t_off: counts_by_verdict.embree_t_off,
        hit_agreement: fraction(hit_mismatch + occlusion_mismatch, rays),
        prim_agreement: fraction(prim_mismatch - certified_ties, log.intersect_queries),
        samples: samples(&log.differences, &verdicts),
    }
}

fn samples(differences: &[Difference], verdicts: &[Verdict]) -> Vec<DisagreementRecord> {
    let mut order: Vec<usize> = (0..differences.len()).collect();
    order.sort_by_key(|&i| verdicts[i]);
    order
        .into_iter()
        .take(SAMPLE_LIMIT)
        .map(|i| record(&differences[i], verdicts[i]))
        .collect()
}

fn record(difference: &Difference, verdict: Verdict) -> DisagreementRecord {
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
        query,
        verdict: verdict.name(),
        ray: ray_record(difference.ray()),
        ours,
        embree,
    }
}

fn ray_record(ray: &Ray) -> RayRecord {
    let values = [
        ray.origin.x,
        ray.origin.y,
        ray.origin.z,
        ray.dir.x,
        ray.dir.y,
        ray.dir.z,
        ray.tnear,
        ray.tfar,
    ];
    RayRecord {
        origin: ray.origin.to_array(),
        dir: ray.dir.to_array(),
        tnear: ray.tnear,
        tfar: ray.tfar,
        bits: values.map(|v| format!("{:#010x}", v.to_bits())),
    }
}

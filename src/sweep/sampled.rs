//! Sampling error against time on one scene: renders at each count of the
//! swept samples ([`SweptCount`]), with stratified and with independent
//! samples, over several seeds, each timed and measured against the
//! scene's exact image (where [`analytic_image`] has its closed form) or a
//! converged, cached reference ([`reference()`]); then the slopes, what
//! stratification buys at equal time, and ours against Embree on the same
//! sample sequences.

use super::analytic::analytic_image;
use super::equal_time::{Curve, EqualError, EqualTime, equal_error, equal_time};
use super::metrics::{mean_flip, rel_mse};
use super::reference::{ReferenceSummary, reference};
use super::spread::Spread;
use super::swept::SweptCount;
use crate::backends::embree::EMBREE;
use crate::backends::ours::OURS;
use crate::check::layered::{LayeredBackend, render_checked};
use crate::fit::{LogLogFit, fit_log_log};
use crate::parallel::Workers;
use crate::render::image::Image;
use crate::render::sampling::Sampler;
use crate::results::Verdicts;
use crate::scene::Scene;
use anyhow::Context;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// The confidence of every slope's interval.
pub const CONFIDENCE: f64 = 0.95;

/// The largest counts the slopes against time are fitted over. A render's
/// time is a fixed part (primary rays, and the pixels that sample
/// nothing) plus a part proportional to the count; at the smallest counts
/// the fixed part dominates, the time hardly grows, and a fit through
/// them would read that as a steeper fall of error with time.
pub const TIME_FIT_COUNTS: usize = 3;

/// How big a sweep of one scene is.
#[derive(Clone, Debug)]
pub struct SampledPlan {
    pub resolution: u32,
    /// The sample counts, ascending; each fills its stratification.
    pub counts: Vec<u32>,
    pub seeds: u32,
    /// Samples of each reference half.
    pub reference_samples_per_half: u32,
}

/// What the errors are measured against.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Target {
    /// The scene's exact image (no bias can hide in it).
    Analytic,
    /// A converged render by the same code.
    Reference,
}

/// The sweep of one scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSweep {
    pub scene: String,
    pub swept: SweptCount,
    pub resolution: u32,
    pub seeds: u32,
    pub target: Target,
    /// The reference and how well it is converged; `None` against the
    /// analytic image.
    pub reference: Option<ReferenceCheck>,
    /// Stratified, then independent.
    pub samplers: Vec<SamplerCurve>,
    /// Both samplers' relMSE at the times of the stratified counts.
    pub equal_time: Vec<EqualTime>,
    /// Both samplers' times to the relMSE of the independent counts.
    pub equal_error: Vec<EqualError>,
    /// Ours against Embree on the same sample sequences, per count.
    pub embree: Vec<EmbreeDifference>,
}

/// A reference and its margin below the errors it measures.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceCheck {
    #[serde(flatten)]
    pub summary: ReferenceSummary,
    /// The smallest mean relMSE of the sweep.
    pub smallest_swept_rel_mse: f64,
    /// That over the reference's own relMSE.
    pub margin: f64,
    /// Whether the margin is at least [`REQUIRED_MARGIN`].
    pub converged_enough: bool,
}

/// How far below the smallest error swept a reference's own error must be.
pub const REQUIRED_MARGIN: f64 = 10.0;

/// One sampler's measurements and fits.
#[derive(Clone, Debug, Serialize)]
pub struct SamplerCurve {
    /// `stratified` or `independent`.
    pub sampler: String,
    pub points: Vec<CountPoint>,
    pub fits: Fits,
}

/// Power laws fitted over every seed's render: against samples over every
/// count, against time over the [`TIME_FIT_COUNTS`] largest. A FLIP fit is
/// `None` when fewer than three renders differ from the target at all
/// once tone-mapped to 8 bits.
#[derive(Clone, Debug, Serialize)]
pub struct Fits {
    pub rel_mse_vs_samples: LogLogFit,
    pub rel_mse_vs_seconds: LogLogFit,
    pub flip_vs_samples: Option<LogLogFit>,
    pub flip_vs_seconds: Option<LogLogFit>,
}

/// The renders of one count, over seeds.
#[derive(Clone, Debug, Serialize)]
pub struct CountPoint {
    pub samples: u32,
    pub seconds: Spread,
    pub rel_mse: Spread,
    pub flip: Spread,
    /// Every seed's render.
    pub runs: Vec<SeedRun>,
}

/// One render.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SeedRun {
    pub seed: u64,
    pub seconds: f64,
    pub rel_mse: f64,
    pub flip: f64,
}

/// Ours against Embree at one count: the same seed, sampler and settings,
/// so the same sample sequences; any difference comes from the hits.
#[derive(Clone, Debug, Serialize)]
pub struct EmbreeDifference {
    pub samples: u32,
    /// relMSE of Embree's render against ours.
    pub rel_mse: f64,
    /// The noise at this count: ours' mean relMSE against the target.
    pub noise_rel_mse: f64,
    pub pixels: usize,
    /// Pixels whose value differs in any bit.
    pub differing_pixels: usize,
    /// The largest difference of a channel, linear.
    pub max_difference: f32,
    /// The referee's verdicts on the queries of Embree's render, asked of
    /// both (Embree first): disagreements, ambiguous ones, and each
    /// backend's wrong answers.
    pub verdicts: Verdicts,
}

const SAMPLERS: [(Sampler, &str); 2] = [
    (Sampler::Stratified, "stratified"),
    (Sampler::Independent, "independent"),
];

/// Sweeps `scene` on `workers`, rendering with ours (the wide BVH) and
/// Embree MEDIUM for the comparison, with references cached in `cache`.
///
/// # Errors
/// The scene samples nothing, a backend cannot be built, or the reference
/// cannot be cached.
pub fn sweep_scene(
    scene: &Scene,
    plan: &SampledPlan,
    workers: &Workers,
    cache: &Path,
    progress: &dyn Fn(&str),
) -> anyhow::Result<SceneSweep> {
    let name = &scene.name;
    let swept = SweptCount::of(scene)
        .with_context(|| format!("{name}: its render samples nothing a sweep can count"))?;
    let pool = workers.pool();
    let backends = [
        LayeredBackend::build(&EMBREE, scene, workers.build_context())?,
        LayeredBackend::build(&OURS, scene, workers.build_context())?,
    ];
    let ours = &backends[1];
    let configure = |count: u32, sampler: Sampler, seed: u64| {
        swept.configure(scene, count, plan.resolution, sampler, seed)
    };
    let (first, settings) = configure(1, Sampler::Stratified, 0);
    let analytic = pool.install(|| analytic_image(&first, ours.layers[0].as_ref(), &settings));
    let (target, reference) = match analytic {
        Ok(image) => ((Target::Analytic, image), None),
        Err(_) => {
            progress(&format!("{name}: converged reference"));
            let per_half = plan.reference_samples_per_half;
            let r = pool.install(|| {
                reference(scene, ours, cache, per_half, &|seed| {
                    configure(per_half, super::reference::SAMPLER, seed)
                })
            })?;
            ((Target::Reference, r.image), Some(r.summary))
        }
    };
    let (target, target_image) = target;

    // One untimed render first, so no timed one pays for cold caches.
    let (configured, settings) = configure(plan.counts[0], Sampler::Stratified, 0);
    std::hint::black_box(pool.install(|| ours.render(&configured, &settings)));
    // Counts outermost and both samplers in turn per seed, so a change of
    // the machine's load falls on both alike.
    let mut runs: [Vec<Vec<SeedRun>>; 2] = Default::default();
    let mut first_seed: Vec<Image> = Vec::new();
    for &count in &plan.counts {
        progress(&format!("{name}: {count} {}", swept.name()));
        let mut at_count: [Vec<SeedRun>; 2] = Default::default();
        for seed in 0..plan.seeds as u64 {
            for (s, &(sampler, _)) in SAMPLERS.iter().enumerate() {
                let (configured, settings) = configure(count, sampler, seed);
                let started = Instant::now();
                let image = pool.install(|| ours.render(&configured, &settings));
                let seconds = started.elapsed().as_secs_f64();
                at_count[s].push(SeedRun {
                    seed,
                    seconds,
                    rel_mse: rel_mse(&image, &target_image)?,
                    flip: mean_flip(&image, &target_image)?,
                });
                if seed == 0 && sampler == Sampler::Stratified {
                    first_seed.push(image);
                }
            }
        }
        for (all, these) in runs.iter_mut().zip(at_count) {
            all.push(these);
        }
    }
    let samplers = SAMPLERS
        .iter()
        .zip(&runs)
        .map(|(&(_, label), runs)| curve(label, &plan.counts, runs))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let as_curve = |c: &SamplerCurve| -> Vec<(u32, f64, f64)> {
        c.points
            .iter()
            .map(|p| (p.samples, p.seconds.mean, p.rel_mse.mean))
            .collect()
    };
    let (stratified, independent) = (as_curve(&samplers[0]), as_curve(&samplers[1]));
    let stratified = Curve {
        points: &stratified,
        fit: &samplers[0].fits.rel_mse_vs_seconds,
    };
    let independent = Curve {
        points: &independent,
        fit: &samplers[1].fits.rel_mse_vs_seconds,
    };

    progress(&format!("{name}: ours against Embree"));
    let mut embree = Vec::new();
    for (&count, ours_image) in plan.counts.iter().zip(&first_seed) {
        let (configured, settings) = configure(count, Sampler::Stratified, 0);
        let checked = pool.install(|| render_checked(&configured, &backends, &settings));
        let verdicts = Verdicts::judge_layers(&configured, &checked.logs);
        let noise = samplers[0]
            .points
            .iter()
            .find(|p| p.samples == count)
            .map_or(f64::NAN, |p| p.rel_mse.mean);
        embree.push(difference(
            count,
            &checked.image,
            ours_image,
            noise,
            verdicts,
        )?);
    }

    let smallest = samplers
        .iter()
        .flat_map(|c| &c.points)
        .map(|p| p.rel_mse.mean)
        .fold(f64::INFINITY, f64::min);
    Ok(SceneSweep {
        scene: name.clone(),
        swept,
        resolution: plan.resolution,
        seeds: plan.seeds,
        target,
        reference: reference.map(|summary| {
            let margin = smallest / summary.rel_mse;
            ReferenceCheck {
                summary,
                smallest_swept_rel_mse: smallest,
                margin,
                converged_enough: margin >= REQUIRED_MARGIN,
            }
        }),
        equal_time: equal_time(stratified, independent),
        equal_error: equal_error(stratified, independent),
        samplers,
        embree,
    })
}

/// The points and fits of one sampler, from its runs per count.
fn curve(label: &str, counts: &[u32], runs: &[Vec<SeedRun>]) -> anyhow::Result<SamplerCurve> {
    let points = counts
        .iter()
        .zip(runs)
        .map(|(&samples, runs)| {
            let of = |f: fn(&SeedRun) -> f64| Spread::of(&runs.iter().map(f).collect::<Vec<_>>());
            Ok(CountPoint {
                samples,
                seconds: of(|r| r.seconds)?,
                rel_mse: of(|r| r.rel_mse)?,
                flip: of(|r| r.flip)?,
                runs: runs.clone(),
            })
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let largest = &points[points.len().saturating_sub(TIME_FIT_COUNTS)..];
    let pairs =
        |points: &[CountPoint], x: fn(&CountPoint, &SeedRun) -> f64, y: fn(&SeedRun) -> f64| {
            points
                .iter()
                .flat_map(|p| p.runs.iter().map(move |r| (x(p, r), y(r))))
                .filter(|&(_, y)| y > 0.0)
                .collect::<Vec<_>>()
        };
    let by_samples = |p: &CountPoint, _: &SeedRun| p.samples as f64;
    let by_seconds = |_: &CountPoint, r: &SeedRun| r.seconds;
    let fit = |points: Vec<(f64, f64)>| fit_log_log(&points, CONFIDENCE);
    Ok(SamplerCurve {
        sampler: label.to_string(),
        fits: Fits {
            rel_mse_vs_samples: fit(pairs(&points, by_samples, |r| r.rel_mse))
                .with_context(|| format!("{label}: relMSE against samples"))?,
            rel_mse_vs_seconds: fit(pairs(largest, by_seconds, |r| r.rel_mse))
                .with_context(|| format!("{label}: relMSE against time"))?,
            flip_vs_samples: fit(pairs(&points, by_samples, |r| r.flip)).ok(),
            flip_vs_seconds: fit(pairs(largest, by_seconds, |r| r.flip)).ok(),
        },
        points,
    })
}

fn difference(
    samples: u32,
    embree: &Image,
    ours: &Image,
    noise_rel_mse: f64,
    verdicts: Verdicts,
) -> anyhow::Result<EmbreeDifference> {
    let pairs = || embree.pixels.iter().zip(&ours.pixels);
    Ok(EmbreeDifference {
        samples,
        rel_mse: rel_mse(embree, ours)?,
        noise_rel_mse,
        pixels: ours.pixels.len(),
        differing_pixels: pairs().filter(|(a, b)| a != b).count(),
        max_difference: pairs()
            .map(|(a, b)| (*a - *b).abs().max_element())
            .fold(0.0, f32::max),
        verdicts,
    })
}

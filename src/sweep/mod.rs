//! `raycheck sweep`: error against run time, and what each sample, each
//! BVH and robustness buy.
//!
//! Three parts, each on its own list of scenes (or on the scenes named):
//!
//! - sampling error against time ([`sampled`]): every scene with a sampled
//!   feature rendered at 1, 4, 16, … of the samples it takes
//!   ([`swept`]), stratified and independent, over several seeds, against
//!   its exact image ([`analytic`]) or a converged reference cached on disk
//!   ([`mod@reference`]): relMSE and FLIP ([`metrics`]) with their spread over
//!   seeds ([`spread`]), log-log slopes ([`crate::fit`]), equal-time comparisons
//!   ([`equal_time`]), ours against Embree on the same samples;
//! - BVH choices ([`bvh_choices`]): build and frame time, SAH cost and
//!   memory of median, SAH, wide and Embree builds, and when each pays for
//!   its build ([`break_even`]);
//! - robustness against speed ([`robustness`]).
//!
//! The statistics are pure functions; [`chi2`] tests direction samplers
//! against their densities.

pub mod analytic;
pub mod break_even;
pub mod bvh_choices;
pub mod chi2;
pub mod equal_time;
pub mod metrics;
pub mod reference;
pub mod robustness;
pub mod sampled;
pub mod spread;
pub mod swept;
pub mod tables;

use crate::backends::BackendName;
use crate::results::RunMeta;
use crate::run::RunContext;
use crate::scene::{self, Scene};
use crate::stability::{self, CaseResult};
use bvh_choices::{BvhChoice, BvhPlan, BvhScene};
use robustness::{Robustness, RobustnessPlan, measure_robustness};
use sampled::{SampledPlan, SceneSweep, sweep_scene};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;
use swept::SweptCount;

/// The scenes with sampled features, swept by default.
pub const SAMPLED_SCENES: [&str; 6] = [
    "cornell-area",
    "cornell-segment",
    "cornell-glossy",
    "motion-blur",
    "cornell-sampled",
    "analytic-area",
];

/// The scenes whose BVH choices are measured by default.
pub const BVH_SCENES: [&str; 5] = [
    "monkey",
    "dragon-11k",
    "dragon-48k",
    "dragon-203k",
    "dragon-871k",
];

/// Those of a quick sweep.
pub const QUICK_BVH_SCENES: [&str; 2] = ["monkey", "dragon-11k"];

/// What to sweep and how big.
#[derive(Clone, Debug, Default)]
pub struct SweepOptions {
    /// Only these scenes, in every part that applies to them; empty: each
    /// part's own list.
    pub scenes: Vec<String>,
    /// Smaller images, fewer counts, choices and scenes.
    pub quick: bool,
}

impl SweepOptions {
    /// The sampled sweep's size: counts that fill the 2D stratification
    /// (perfect squares), 8 seeds, references of 16 times the largest
    /// count per half.
    pub fn sampled_plan(&self) -> SampledPlan {
        let counts: Vec<u32> = if self.quick {
            vec![1, 4, 16, 64]
        } else {
            vec![1, 4, 16, 64, 256]
        };
        let largest = *counts.last().expect("counts");
        SampledPlan {
            resolution: if self.quick { 48 } else { 128 },
            reference_samples_per_half: 16 * largest,
            counts,
            seeds: 8,
        }
    }

    pub fn bvh_plan(&self) -> BvhPlan {
        BvhPlan {
            choices: BvhChoice::all(self.quick),
            frame_resolution: if self.quick { 192 } else { 512 },
            runs: if self.quick { 1 } else { 3 },
        }
    }

    pub fn robustness_plan(&self) -> RobustnessPlan {
        RobustnessPlan {
            resolution: if self.quick { 128 } else { 256 },
            runs: if self.quick { 1 } else { 3 },
        }
    }

    /// The scene names of each part: sampled, BVH, robustness.
    fn scene_lists(&self) -> [Vec<String>; 3] {
        let owned = |names: &[&str]| names.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        if !self.scenes.is_empty() {
            return [
                self.scenes.clone(),
                self.scenes.clone(),
                self.scenes.clone(),
            ];
        }
        [
            owned(&SAMPLED_SCENES),
            owned(if self.quick {
                &QUICK_BVH_SCENES
            } else {
                &BVH_SCENES
            }),
            owned(scene::benchmark_scenes(self.quick)),
        ]
    }
}

/// Everything a sweep measured; the JSON of `raycheck sweep --json`.
#[derive(Clone, Debug, Serialize)]
pub struct SweepReport {
    pub meta: RunMeta,
    pub quick: bool,
    /// The sampling error of every scene that samples something.
    pub sampled: Vec<SceneSweep>,
    /// The BVH choices on every static scene.
    pub bvh: Vec<BvhScene>,
    pub robustness: Robustness,
    pub timing: Timing,
}

/// Where the run's time went, and how loaded the machine was.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    pub sampled_seconds: f64,
    /// Of those, rendering references not found in the cache.
    pub references_rendered_seconds: f64,
    pub bvh_seconds: f64,
    pub robustness_seconds: f64,
    pub total_seconds: f64,
    /// `/proc/loadavg`'s 1, 5 and 15 minute averages at the start and end.
    pub load_average_start: Option<[f64; 3]>,
    pub load_average_end: Option<[f64; 3]>,
}

/// Runs the quick stability catalogue (ours, Embree, Embree ROBUST) for
/// the robustness part, then the sweep, on the run's workers.
///
/// # Errors
/// A scene does not load (checked before anything runs), a backend cannot
/// be built or a reference cannot be cached.
pub fn run(
    run: &RunContext,
    options: &SweepOptions,
    progress: &dyn Fn(&str),
) -> anyhow::Result<SweepReport> {
    let started = Instant::now();
    let scenes = Scenes::load(options)?;
    progress("robustness: the quick stability catalogue");
    let backends = BackendName::defaults();
    let context = stability::Context {
        backends: &backends,
        build: run.build_context(),
        quick: true,
        recorder: None,
    };
    let catalogue = run.install(|| stability::run_catalogue(&context, None));
    measure(run, options, &scenes, &catalogue, started, progress)
}

/// The sweep, with the robustness part's catalogue points taken from
/// `catalogue` (results of ours, Embree and Embree ROBUST) rather than
/// run again.
///
/// # Errors
/// As [`run`].
pub fn run_with_catalogue(
    run: &RunContext,
    options: &SweepOptions,
    catalogue: &[CaseResult],
    progress: &dyn Fn(&str),
) -> anyhow::Result<SweepReport> {
    let started = Instant::now();
    let scenes = Scenes::load(options)?;
    measure(run, options, &scenes, catalogue, started, progress)
}

/// The scenes of each part, each loaded once.
struct Scenes {
    loaded: BTreeMap<String, Scene>,
    /// Names per part: sampled, BVH, robustness.
    parts: [Vec<String>; 3],
}

impl Scenes {
    fn load(options: &SweepOptions) -> anyhow::Result<Self> {
        let parts = options.scene_lists();
        let mut loaded = BTreeMap::new();
        for name in parts.iter().flatten() {
            if !loaded.contains_key(name) {
                loaded.insert(name.clone(), scene::load(name)?);
            }
        }
        Ok(Self { loaded, parts })
    }

    fn part(&self, index: usize) -> impl Iterator<Item = &Scene> {
        self.parts[index].iter().map(|name| &self.loaded[name])
    }
}

fn measure(
    run: &RunContext,
    options: &SweepOptions,
    scenes: &Scenes,
    catalogue: &[CaseResult],
    started: Instant,
    progress: &dyn Fn(&str),
) -> anyhow::Result<SweepReport> {
    let workers = run.workers();
    let load_average_start = crate::results::meta::load_average();

    let clock = Instant::now();
    let plan = options.sampled_plan();
    let cache = reference::cache_folder()?;
    let mut sampled = Vec::new();
    for scene in scenes.part(0).filter(|s| SweptCount::of(s).is_some()) {
        sampled.push(sweep_scene(scene, &plan, workers, &cache, progress)?);
    }
    let sampled_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    let plan = options.bvh_plan();
    let mut bvh = Vec::new();
    for scene in scenes.part(1).filter(|s| s.moving.is_empty()) {
        bvh.push(bvh_choices::measure_scene(scene, &plan, workers, progress)?);
    }
    let bvh_seconds = clock.elapsed().as_secs_f64();

    let clock = Instant::now();
    let robustness_scenes: Vec<&Scene> = scenes.part(2).collect();
    let robustness = measure_robustness(
        &robustness_scenes,
        catalogue,
        &options.robustness_plan(),
        workers,
        progress,
    )?;
    let robustness_seconds = clock.elapsed().as_secs_f64();

    let references_rendered_seconds = sampled
        .iter()
        .filter_map(|s| s.reference.as_ref())
        .filter(|r| !r.summary.cached)
        .map(|r| r.summary.seconds)
        .fold(0.0, |total, s| total + s);
    Ok(SweepReport {
        meta: run.meta().clone(),
        quick: options.quick,
        sampled,
        bvh,
        robustness,
        timing: Timing {
            sampled_seconds,
            references_rendered_seconds,
            bvh_seconds,
            robustness_seconds,
            total_seconds: started.elapsed().as_secs_f64(),
            load_average_start,
            load_average_end: crate::results::meta::load_average(),
        },
    })
}

//! `raycheck report`: the page of the main job, read top-down.
//!
//! [`write_report`] measures everything into one [`ReportData`] (written
//! as `report.json`), and [`page`] turns it into `index.html` and
//! `report.md`, every table also as CSV under `tables/` and in
//! `tables.json`. The page opens with a summary ([`summary`]) read from
//! the same data as the sections below it, then the contents, then the
//! sections in reading order: agreement with Embree on every scene
//! ([`agreement`]), third-party tracers ([`tracers`]), the feature gallery
//! ([`gallery`]), performance ([`performance`]), numerical stability
//! ([`stability`]) and error against run time ([`sweep`]). Every table and figure carries the machine, date,
//! commit and thread count. Sections too slow for the default run run in
//! their quick form, and the page says so; `--full` runs everything.

pub mod agreement;
pub mod gallery;
pub mod measure;
pub mod page;
pub mod performance;
pub mod plot;
pub mod section;
pub mod stability;
mod style;
pub mod summary;
pub mod sweep;
pub mod tracers;

use crate::backends::{BackendName, DEFAULT_BACKENDS, EMBREE_ROBUST, OurBuilder};
use crate::parallel::thread_pool;
use crate::perf::{PerfOptions, PerfReport};
use crate::results::{CompareSummary, RunMeta, compare_scene};
use crate::scene;
use crate::stability::CaseResult;
use crate::sweep::{SweepOptions, SweepReport};
use gallery::Gallery;
use indicatif::{ProgressBar, ProgressStyle};
use measure::{SceneMeasurements, measure_scene};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

/// How much of everything a report runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Form {
    /// Three small scenes, small images, quick forms throughout: a smoke run.
    Quick,
    /// Every scene; the quick forms of the sections whose full form does
    /// not fit the report's time budget.
    Standard,
    /// Everything in its full form.
    Full,
}

#[derive(Clone, Debug)]
pub struct ReportOptions {
    pub out: PathBuf,
    pub form: Form,
    pub threads: Option<usize>,
    /// A folder of runs saved with `raycheck perf --json`, plotted as the
    /// performance history when it holds any.
    pub history: Option<PathBuf>,
}

/// The third-party crates the tracers section checks beside ours.
pub const THIRD_PARTY: [BackendName; 3] = [
    BackendName::Obvhs,
    BackendName::BvhCrate,
    BackendName::Parry3d,
];

impl ReportOptions {
    fn quick(&self) -> bool {
        self.form == Form::Quick
    }

    pub fn resolution(&self) -> u32 {
        if self.quick() { 256 } else { 800 }
    }

    /// The side of the feature gallery's images.
    pub fn gallery_resolution(&self) -> u32 {
        if self.quick() { 96 } else { 400 }
    }

    pub fn scenes(&self) -> &'static [&'static str] {
        scene::benchmark_scenes(self.quick())
    }

    /// Timed runs per backend in the course table, after the warm-up.
    pub fn runs(&self) -> usize {
        if self.quick() { 2 } else { 3 }
    }

    /// Primary rays per side for the tracers section's compare runs.
    pub fn tracer_resolution(&self) -> u32 {
        match self.form {
            Form::Quick => 96,
            Form::Standard => 256,
            Form::Full => 512,
        }
    }

    /// Whether the stability catalogue runs in its quick form.
    pub fn quick_stability(&self) -> bool {
        self.form != Form::Full
    }

    /// Every backend the tracers, performance and stability sections run:
    /// ours, Embree default and robust, then the third-party crates.
    pub fn backends(&self) -> anyhow::Result<Vec<BackendName>> {
        let mut names = BackendName::parse_list(DEFAULT_BACKENDS)?;
        names.extend(THIRD_PARTY);
        Ok(names)
    }

    /// The backends of the tracers section: ours, the crates, then Embree
    /// robust as the second opinion.
    pub fn tracer_backends(&self) -> Vec<BackendName> {
        let mut names = vec![BackendName::Ours(OurBuilder::Wide)];
        names.extend(THIRD_PARTY);
        names.push(BackendName::Embree(EMBREE_ROBUST));
        names
    }

    /// Every built-in scene without moving meshes (quick: the quick three).
    pub fn tracer_scenes(&self) -> anyhow::Result<Vec<String>> {
        if self.quick() {
            return Ok(self.scenes().iter().map(|s| s.to_string()).collect());
        }
        let mut names = Vec::new();
        for name in scene::builtin_names()? {
            if scene::load(&name)?.moving.is_empty() {
                names.push(name);
            }
        }
        Ok(names)
    }
}

/// Everything the report measured; `report.json`.
#[derive(Serialize)]
pub struct ReportData {
    pub meta: RunMeta,
    pub form: Form,
    pub scenes: Vec<SceneMeasurements>,
    /// Ours, the third-party crates and Embree robust on every scene.
    pub tracers: Vec<CompareSummary>,
    pub gallery: Gallery,
    pub performance: PerfReport,
    /// Runs saved with `raycheck perf --json` in the history folder, oldest
    /// first.
    pub history: Vec<PerfReport>,
    /// Whether the catalogue ran in its quick form.
    pub stability_quick: bool,
    pub stability: Vec<CaseResult>,
    /// Error against run time (the sweep's quick form unless `--full`).
    pub sweep: SweepReport,
    /// Seconds each part of the report took, in order.
    pub timings: Vec<(String, f64)>,
}

/// Measures everything and writes the report folder; returns the path of
/// its `index.html`.
pub fn write_report(options: &ReportOptions) -> anyhow::Result<PathBuf> {
    let pool = thread_pool(options.threads)?;
    let threads = pool.current_num_threads();
    let meta = RunMeta::collect(threads);
    let device = crate::backends::embree_device(threads)?;
    let scenes = options.scenes();
    let tracer_scenes = options.tracer_scenes()?;
    let backends = options.backends()?;
    let bar = ProgressBar::new((scenes.len() + tracer_scenes.len() + 5) as u64);
    bar.set_style(
        ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {pos}/{len} {msg}")?
            .progress_chars("=> "),
    );
    let step = |name: &str| bar.set_message(name.to_string());
    let mut timings = Timings::start();

    let mut measured = Vec::new();
    for name in scenes {
        step(&format!("agreement and course table: {name}: loading"));
        let scene = scene::load(name)?;
        let progress = |what: &str| step(&format!("agreement and course table: {name}: {what}"));
        measured.push(pool.install(|| {
            measure_scene(
                &scene,
                &device,
                options.resolution(),
                options.runs(),
                &progress,
            )
        })?);
        bar.inc(1);
    }
    timings.lap("agreement and course tables");
    let mut tracers = Vec::new();
    for name in &tracer_scenes {
        step(&format!("third-party tracers: {name}"));
        let scene = scene::load(name)?;
        tracers.push(pool.install(|| {
            compare_scene(
                &scene,
                &options.tracer_backends(),
                &device,
                options.tracer_resolution(),
            )
        })?);
        bar.inc(1);
    }
    timings.lap("third-party tracers");
    step("feature gallery");
    let gallery = pool.install(|| gallery::measure(&device, options.gallery_resolution()))?;
    bar.inc(1);
    timings.lap("feature gallery");
    let perf = crate::perf::run(
        &PerfOptions {
            quick: options.quick(),
            threads: Some(threads),
            backends: backends.clone(),
            embree_isa: raycheck_reference::Isa::Auto,
        },
        &|what| step(&format!("performance: {what}")),
    )?;
    bar.inc(1);
    timings.lap("performance");
    step("numerical stability: the catalogue");
    let context = crate::stability::Context {
        backends: &backends,
        device: &device,
        quick: options.quick_stability(),
        recorder: None,
    };
    let stability = pool.install(|| crate::stability::run_catalogue(&context, None));
    bar.inc(1);
    timings.lap("numerical stability");
    let sweep = crate::sweep::run_with_catalogue(
        &SweepOptions {
            scenes: Vec::new(),
            quick: options.form != Form::Full,
            threads: Some(threads),
        },
        &stability,
        &|what| step(&format!("error against run time: {what}")),
    )?;
    bar.inc(1);
    timings.lap("error against run time");
    step("performance history");
    let history = performance::history(options.history.as_deref())?;
    bar.finish_and_clear();
    let data = ReportData {
        meta,
        form: options.form,
        scenes: measured,
        tracers,
        gallery,
        performance: perf,
        history,
        stability_quick: options.quick_stability(),
        stability,
        sweep,
        timings: timings.parts,
    };
    page::write(&options.out, &data)
}

/// How long each part of the report took, in seconds, in order.
struct Timings {
    parts: Vec<(String, f64)>,
    since: Instant,
}

impl Timings {
    fn start() -> Self {
        Self {
            parts: Vec::new(),
            since: Instant::now(),
        }
    }

    /// Ends the part `name`, begun when the last one ended (or at the
    /// start).
    fn lap(&mut self, name: &str) {
        let now = Instant::now();
        let seconds = (now - self.since).as_secs_f64();
        self.parts.push((name.to_string(), seconds));
        self.since = now;
    }
}

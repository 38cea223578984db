//! `raycheck report`: the tables, images and page of the main job.
//!
//! For each scene: the classic course-report performance table (triangles,
//! BVH build time, render time, BVH levels, max triangles per leaf) for the
//! median build, the SAH build and Embree side by side; the render as PNG
//! and as linear EXR; and the agreement table of `raycheck compare`. Then
//! the feature gallery ([`gallery`]): each feature scene's render, debug
//! view and render times. The performance section ([`performance`]) adds
//! our fast path beside Embree MEDIUM and ROBUST, `raycheck perf`'s
//! throughput tables and the scaling plots; the stability section
//! ([`stability`]) the catalogue of `raycheck stability` (quick under
//! `--quick`). Every
//! table and figure carries the machine, date, commit and thread count.
//! Written as `index.html`, `report.md` and `report.json` in one folder.

pub mod gallery;
pub mod measure;
pub mod page;
pub mod performance;
pub mod plot;
pub mod section;
pub mod stability;

use crate::backends::{BackendName, DEFAULT_BACKENDS};
use crate::parallel::thread_pool;
use crate::results::RunMeta;
use crate::scene;
use indicatif::{ProgressBar, ProgressStyle};
use measure::{COURSE_BACKENDS, SceneMeasurements, measure_scene};
use std::path::PathBuf;

#[derive(Clone, Debug)]
pub struct ReportOptions {
    pub out: PathBuf,
    pub quick: bool,
    pub threads: Option<usize>,
}

impl ReportOptions {
    pub fn resolution(&self) -> u32 {
        if self.quick { 256 } else { 800 }
    }

    /// The side of the feature gallery's images.
    pub fn gallery_resolution(&self) -> u32 {
        if self.quick { 96 } else { 400 }
    }

    pub fn scenes(&self) -> &'static [&'static str] {
        scene::benchmark_scenes(self.quick)
    }

    /// Timed runs per backend in the course table, after the warm-up.
    pub fn runs(&self) -> usize {
        if self.quick { 2 } else { 3 }
    }

    /// Progress-bar steps per scene: loading, a warm-up per course
    /// backend, the timed runs, the agreement.
    fn steps_per_scene(&self) -> u64 {
        (2 + COURSE_BACKENDS.len() + self.runs()) as u64
    }
}

/// Measures every scene and writes the report folder; returns the path of
/// its `index.html`.
pub fn write_report(options: &ReportOptions) -> anyhow::Result<PathBuf> {
    let pool = thread_pool(options.threads)?;
    let threads = pool.current_num_threads();
    let meta = RunMeta::collect(threads);
    let device = crate::backends::embree_device(threads)?;
    let scenes = options.scenes();
    let bar = ProgressBar::new(scenes.len() as u64 * options.steps_per_scene());
    bar.set_style(
        ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {pos}/{len} {msg}")?
            .progress_chars("=> "),
    );
    let mut sections: Vec<SceneMeasurements> = Vec::new();
    for name in scenes {
        bar.set_message(format!("{name}: loading"));
        let scene = scene::load(name)?;
        bar.inc(1);
        let progress = |step: &str| {
            bar.set_message(format!("{name}: {step}"));
            bar.inc(1);
        };
        let measured = pool.install(|| {
            measure_scene(
                &scene,
                &device,
                options.resolution(),
                options.runs(),
                &progress,
            )
        })?;
        sections.push(measured);
    }
    bar.set_message("feature gallery");
    let gallery = pool.install(|| gallery::measure(&device, options.gallery_resolution()))?;
    bar.set_message("performance: ours and Embree in turn");
    let backends = BackendName::parse_list(DEFAULT_BACKENDS)?;
    let perf = crate::perf::run(
        &crate::perf::PerfOptions {
            quick: options.quick,
            threads: Some(threads),
            backends: backends.clone(),
        },
        &|step| bar.set_message(format!("performance: {step}")),
    )?;
    bar.set_message("numerical stability: the catalogue");
    let context = crate::stability::Context {
        backends: &backends,
        device: &device,
        quick: options.quick,
        recorder: None,
    };
    let stability = pool.install(|| crate::stability::run_catalogue(&context, None));
    bar.finish_and_clear();
    page::write(&options.out, &meta, &sections, &gallery, &perf, &stability)
}

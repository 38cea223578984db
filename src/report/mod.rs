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

use crate::backends::embree::EMBREE_ROBUST;
use crate::backends::ours::OURS;
use crate::backends::{BackendName, Group};
use crate::exchange::program::{ProgramRun, with_programs};
use crate::perf::{PerfOptions, PerfReport};
use crate::results::{CompareSummary, RunMeta, compare_scene};
use crate::run::{Form, RunContext};
use crate::scene;
use crate::stability::CaseResult;
use crate::sweep::{SweepOptions, SweepReport};
use gallery::Gallery;
use indicatif::{ProgressBar, ProgressStyle};
use measure::{Runs, SceneMeasurements, measure_scene};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct ReportOptions {
    pub out: PathBuf,
    /// A folder of runs saved with `raycheck perf --json`, plotted as the
    /// performance history when it holds any.
    pub history: Option<PathBuf>,
}

/// What the report runs in a form: scenes, sizes and backends of each
/// section.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub form: Form,
}

impl Plan {
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

    /// Renders per backend whose split into tracing, shading and image
    /// work is taken (each part's median): the medians of three moved by
    /// ±5% between runs, as much as the goal between a render and its
    /// tracing allows.
    pub fn split_renders(&self) -> usize {
        if self.quick() { 2 } else { 7 }
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
    /// the default ones (ours, Embree default and robust), then the
    /// third-party tracers.
    pub fn backends(&self) -> Vec<BackendName> {
        let mut names = BackendName::defaults();
        names.extend(third_party());
        names
    }

    /// Those of them the stability section runs: all of them on the quick
    /// catalogue, all but the slow programs on the full one (millions of
    /// rays: hours for an interpreted or brute-force intersector).
    pub fn stability_backends(&self) -> Vec<BackendName> {
        let mut names = self.backends();
        if !self.quick_stability() {
            names.retain(|name| !is_slow(name));
        }
        names
    }

    /// The backends of the tracers section: ours, the third-party
    /// tracers, then Embree robust as the second opinion.
    pub fn tracer_backends(&self) -> Vec<BackendName> {
        let mut names = vec![OURS];
        names.extend(third_party());
        names.push(EMBREE_ROBUST);
        names
    }

    /// Those of them that trace `scene`. A slow program (a brute-force or
    /// interpreted intersector) traces only the quick scenes, in every
    /// form: on the million-triangle dragons it would take hours (the C++
    /// template about 45 minutes on dragon-871k's rays alone), on
    /// dragon-14m days. A scale scene (dragon-14m, full form only) is
    /// traced by ours and Embree robust alone, as in perf: every crate and
    /// program holds its own tree and copy of the mesh, and together they
    /// passed 11 GB on it.
    pub fn tracer_backends_on(&self, scene: &str) -> Vec<BackendName> {
        if scene::SCALE_SCENES.contains(&scene) {
            return vec![OURS, EMBREE_ROBUST];
        }
        let quick_scene = scene::QUICK_SCENES.contains(&scene);
        self.tracer_backends()
            .into_iter()
            .filter(|name| !is_slow(name) || quick_scene)
            .collect()
    }

    /// Every built-in scene without moving meshes (quick: the quick three),
    /// beyond a million triangles only in the full form.
    pub fn tracer_scenes(&self) -> anyhow::Result<Vec<String>> {
        if self.quick() {
            return Ok(self.scenes().iter().map(|s| s.to_string()).collect());
        }
        let mut names = Vec::new();
        for name in scene::builtin_names()? {
            let scale = scene::SCALE_SCENES.contains(&name.as_str());
            if (!scale || self.form.is_full()) && scene::load(&name)?.moving.is_empty() {
                names.push(name);
            }
        }
        Ok(names)
    }
}

/// Whether `name` is a program marked slow, which the report runs on
/// quick inputs only.
fn is_slow(name: &BackendName) -> bool {
    name.program().is_some_and(|p| p.slow)
}

/// Everything the report measured; `report.json`.
#[derive(Serialize)]
pub struct ReportData {
    pub meta: RunMeta,
    pub form: Form,
    pub scenes: Vec<SceneMeasurements>,
    /// Every backend of the tracers section.
    pub tracer_backends: Vec<String>,
    /// Ours, the third-party tracers and Embree robust on every scene
    /// (slow programs on fewer, see [`Plan::tracer_backends_on`]).
    pub tracers: Vec<CompareSummary>,
    /// What the programs among the backends did, part by part.
    pub programs: Vec<ProgramPart>,
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

/// What the programs did in one part of the report (a scene of the
/// tracers section, or the stability catalogue).
#[derive(Clone, Debug, Serialize)]
pub struct ProgramPart {
    pub part: String,
    pub runs: Vec<ProgramRun>,
}

/// The third-party tracers, as the registry groups them: the crates, then
/// the programs.
pub fn third_party() -> Vec<BackendName> {
    let mut names = BackendName::in_group(Group::Crate);
    names.extend(BackendName::in_group(Group::Program));
    names
}

/// Measures everything in the run's form and writes the report folder;
/// returns the path of its `index.html`.
pub fn write_report(run: &RunContext, options: &ReportOptions) -> anyhow::Result<PathBuf> {
    let plan = Plan { form: run.form() };
    let workers = run.workers();
    let scenes = plan.scenes();
    let tracer_scenes = plan.tracer_scenes()?;
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
        measured.push(measure_scene(
            &scene,
            workers,
            plan.resolution(),
            Runs {
                timed: plan.runs(),
                split: plan.split_renders(),
            },
            &progress,
        )?);
        bar.inc(1);
    }
    timings.lap("agreement and course tables");
    let mut tracers = Vec::new();
    let mut programs = Vec::new();
    for name in &tracer_scenes {
        step(&format!("third-party tracers: {name}"));
        let scene = scene::load(name)?;
        let compared = with_programs(
            &plan.tracer_backends_on(name),
            |names| compare_scene(&scene, names, workers, plan.tracer_resolution()),
            &|what| step(&format!("third-party tracers: {name}: {what}")),
        )?;
        tracers.push(compared.value);
        programs.push(ProgramPart {
            part: format!("tracers: {name}"),
            runs: compared.programs,
        });
        bar.inc(1);
    }
    timings.lap("third-party tracers");
    step("feature gallery");
    let gallery = gallery::measure(workers, plan.gallery_resolution())?;
    bar.inc(1);
    timings.lap("feature gallery");
    let perf = crate::perf::run(
        run,
        &PerfOptions {
            form: plan.form,
            thread_counts: vec![run.threads()],
            backends: plan.backends(),
            only_scenes: Vec::new(),
        },
        &|what| step(&format!("performance: {what}")),
    )?;
    bar.inc(1);
    timings.lap("performance");
    step("numerical stability: the catalogue");
    let judged = with_programs(
        &plan.stability_backends(),
        |names| Ok(crate::stability::run(run, names, None)),
        &|what| step(&format!("numerical stability: {what}")),
    )?;
    let stability = judged.value;
    programs.push(ProgramPart {
        part: "stability catalogue".into(),
        runs: judged.programs,
    });
    bar.inc(1);
    timings.lap("numerical stability");
    let sweep = crate::sweep::run_with_catalogue(
        run,
        &SweepOptions {
            scenes: Vec::new(),
            quick: !plan.form.is_full(),
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
        meta: run.meta().clone(),
        form: plan.form,
        scenes: measured,
        tracer_backends: plan
            .tracer_backends()
            .iter()
            .map(|b| b.to_string())
            .collect(),
        tracers,
        programs,
        gallery,
        performance: perf,
        history,
        stability_quick: plan.quick_stability(),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Which backends trace which scene: the scale scene by ours and Embree
    /// robust only, a slow program only the quick scenes, in every form.
    #[test]
    fn each_scene_is_traced_by_the_backends_that_fit_it() {
        let full = Plan { form: Form::Full };
        assert_eq!(
            full.tracer_backends_on("dragon-14m"),
            vec![OURS, EMBREE_ROBUST]
        );
        let slow = |names: &[BackendName]| names.iter().filter(|n| is_slow(n)).count();
        let all = full.tracer_backends();
        assert!(slow(&all) > 0, "no slow program among {all:?}");
        for form in [Form::Quick, Form::Standard, Form::Full] {
            let plan = Plan { form };
            assert_eq!(plan.tracer_backends_on("monkey"), all);
            let large = plan.tracer_backends_on("dragon-871k");
            assert_eq!(slow(&large), 0, "{large:?}");
            assert_eq!(large.len(), all.len() - slow(&all));
        }
    }

    /// The full catalogue runs every backend but the slow programs; the
    /// quick one every backend.
    #[test]
    fn slow_programs_run_only_the_quick_catalogue() {
        let slow = |names: &[BackendName]| names.iter().filter(|n| is_slow(n)).count();
        for form in [Form::Quick, Form::Standard] {
            let plan = Plan { form };
            assert_eq!(plan.stability_backends(), plan.backends());
        }
        let full = Plan { form: Form::Full };
        let names = full.stability_backends();
        assert_eq!(slow(&names), 0, "{names:?}");
        assert!(slow(&full.backends()) > 0);
        assert_eq!(names.len(), full.backends().len() - slow(&full.backends()));
    }
}

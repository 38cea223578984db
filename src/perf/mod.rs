//! `raycheck perf`: every backend side by side in one process.
//!
//! For each scene and thread count, every backend of the list (by default
//! ours, Embree MEDIUM and MEDIUM + ROBUST): build time, throughput of
//! primary, shadow and diffuse rays (the fixed [`rays::RaySets`]), and
//! bytes per triangle, measured in turn, run by run, medians over runs with
//! their range; the ratios to Embree against our goals; then the scaling of
//! build time and time per ray with the triangle count.

pub mod baseline;
#[cfg(test)]
pub mod fixtures;
pub mod measure;
pub mod memory;
pub mod rays;
pub mod scaling;
mod welch;

use crate::backends::embree::{EMBREE, EMBREE_ROBUST};
use crate::backends::ours::OURS;
use crate::backends::{BackendName, Group};
use crate::results::{Cell, RunMeta, Table, Tone};
use crate::run::{Form, RunContext};
use crate::scene;
use anyhow::Context;
use measure::{PerfRow, REPEATED_BUILDS_UP_TO, Stat, measure};
use raycheck_reference::ThreadLimit;
use rays::RaySets;
use scaling::Scaling;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// What `raycheck perf` times, and how much of it.
#[derive(Clone, Debug)]
pub struct PerfOptions {
    pub form: Form,
    /// The thread counts to measure on.
    pub thread_counts: Vec<usize>,
    /// The backends to time, in turn.
    pub backends: Vec<BackendName>,
    /// The built-in scenes to time, in order; empty for the form's own
    /// ([`PerfOptions::scenes`]).
    pub only_scenes: Vec<String>,
}

impl PerfOptions {
    /// The run's form and thread counts (see [`RunContext::thread_counts`]).
    pub fn of_run(run: &RunContext, backends: Vec<BackendName>) -> Self {
        Self {
            form: run.form(),
            thread_counts: run.thread_counts(),
            backends,
            only_scenes: Vec::new(),
        }
    }

    /// Times only `names`, built-in scenes, in that order; an unknown name
    /// is an error that lists the built-in ones.
    pub fn only(mut self, names: Vec<String>) -> anyhow::Result<Self> {
        let known = scene::builtin_names()?;
        if let Some(unknown) = names.iter().find(|n| !known.contains(n)) {
            anyhow::bail!(
                "--scenes: no built-in scene named `{unknown}`; the built-in scenes are {}",
                known.join(", ")
            );
        }
        self.only_scenes = names;
        Ok(self)
    }

    fn quick(&self) -> bool {
        self.form.is_quick()
    }

    /// The scenes asked for, else the benchmark scenes, then in the full
    /// form the scale scenes.
    pub fn scenes(&self) -> Vec<&str> {
        if !self.only_scenes.is_empty() {
            return self.only_scenes.iter().map(String::as_str).collect();
        }
        let mut scenes = crate::scene::benchmark_scenes(self.quick()).to_vec();
        if self.form.is_full() {
            scenes.extend(crate::scene::SCALE_SCENES);
        }
        scenes
    }

    /// The backends timed on `scene`: never a program (it answers through
    /// files; its wall time is shown where it runs, not compared), and on
    /// the scale scenes only ours and Embree (a third-party crate's build
    /// there takes minutes).
    pub fn backends_for(&self, scene: &str) -> Vec<BackendName> {
        let scale = crate::scene::SCALE_SCENES.contains(&scene);
        self.backends
            .iter()
            .filter(|b| b.program().is_none() && !(scale && b.is_third_party()))
            .cloned()
            .collect()
    }

    /// Primary rays per side of the view.
    pub fn resolution(&self) -> u32 {
        if self.quick() { 128 } else { 512 }
    }

    pub fn runs(&self) -> usize {
        if self.quick() { 3 } else { 7 }
    }
}

/// Everything `raycheck perf` measured; its JSON, and a saved run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PerfReport {
    /// The machine, date and commit; `threads` is the largest count measured.
    pub meta: RunMeta,
    /// The traversal kernel our wide BVH ran with (`n/a` when it was not
    /// timed).
    pub kernel: String,
    /// The instruction set Embree selected, as it reported it (`n/a` when
    /// no Embree backend was timed; empty in runs saved before it was
    /// recorded).
    #[serde(default)]
    pub embree_isa: String,
    /// How our queries crossed to Embree
    /// ([`raycheck_reference::BINDING_REVISION`]; 0 in runs saved before
    /// it was recorded).
    #[serde(default)]
    pub embree_binding: u32,
    pub resolution: u32,
    pub runs: usize,
    /// The backends' names, in the order timed.
    pub backends: Vec<String>,
    /// One per scene, thread count and backend.
    pub rows: Vec<PerfRow>,
    /// One per thread count and backend.
    pub scaling: Vec<Scaling>,
}

/// Runs every measurement on the run's workers for each thread count;
/// `progress` hears each step.
pub fn run(
    run: &RunContext,
    options: &PerfOptions,
    progress: &dyn Fn(&str),
) -> anyhow::Result<PerfReport> {
    let thread_counts = &options.thread_counts;
    let meta = RunMeta {
        threads: thread_counts.iter().copied().max().unwrap_or(1),
        ..run.meta().clone()
    };
    let kernel = if options.backends.contains(&OURS) {
        run.sets().kernel.to_string()
    } else {
        "n/a".into()
    };
    // Fewest threads first: Embree builds with the most threads of any
    // live device (see `Workers`), so no larger count's device may exist
    // while a smaller count is measured. oneTBB is held to each count
    // (`ThreadLimit`): a device made after another was released would
    // otherwise leave a worker spinning beside the measurement.
    let mut ascending = thread_counts.clone();
    ascending.sort_unstable();
    let fewest = ascending.first().copied().unwrap_or(1);
    let embree_isa = if options.backends.iter().any(|b| b.group() == Group::Embree) {
        let _limit = ThreadLimit::hold(fewest);
        let selected = run.workers_for(fewest)?.device().selected_isa()?;
        format!(
            "{} (selected, {}; asked {})",
            selected.isa,
            selected.frequency_level,
            run.sets().embree
        )
    } else {
        "n/a".into()
    };
    // Each scene is loaded once per count, one at a time, so memory holds
    // one scene and its trees.
    let mut rows = Vec::new();
    for &threads in &ascending {
        let _limit = ThreadLimit::hold(threads);
        let workers = run.workers_for(threads)?;
        for name in options.scenes() {
            progress(&format!("{name}: {threads} thread(s)"));
            let scene = scene::load(name)?;
            let rays = run.install(|| RaySets::cached(&scene, options.resolution()));
            let backends = options.backends_for(name);
            rows.extend(measure(&scene, &rays, &workers, &backends, options.runs())?);
        }
    }
    let scene_order = options.scenes();
    rows.sort_by_key(|row| {
        let scene = scene_order.iter().position(|s| *s == row.scene);
        (scene, row.threads)
    });
    let backends: Vec<String> = options.backends.iter().map(|b| b.to_string()).collect();
    let scaling = thread_counts
        .iter()
        .flat_map(|&threads| {
            let rows = &rows;
            backends.iter().filter_map(move |backend| {
                let selected: Vec<&PerfRow> = rows
                    .iter()
                    .filter(|r| r.threads == threads && &r.backend == backend)
                    .collect();
                Scaling::from_rows(&selected)
            })
        })
        .collect();
    Ok(PerfReport {
        meta,
        kernel,
        embree_isa,
        embree_binding: raycheck_reference::BINDING_REVISION,
        resolution: options.resolution(),
        runs: options.runs(),
        backends,
        rows,
        scaling,
    })
}

/// The speed goals of our tracer against an Embree configuration, as
/// speed ratios (above 1 is faster; bytes below 1 is smaller): build,
/// primary, shadow, diffuse, and the largest bytes per triangle.
pub struct Goals {
    pub baseline: BackendName,
    pub minimum: [f64; 4],
    pub maximum_bytes: f64,
}

/// Ours against Embree MEDIUM (`rtcIntersect1` / `rtcOccluded1`) and
/// against MEDIUM + ROBUST, the like-for-like rival of a watertight tracer.
pub const GOALS: [Goals; 2] = [
    Goals {
        baseline: EMBREE,
        minimum: [1.0, 1.0, 1.0, 0.9],
        maximum_bytes: 1.0,
    },
    Goals {
        baseline: EMBREE_ROBUST,
        minimum: [1.0, 1.0, 1.0, 1.0],
        maximum_bytes: 1.0,
    },
];

/// `median [min–max]` with `decimals` digits.
fn spread(stat: &Stat, decimals: usize) -> String {
    format!(
        "{:.d$} [{:.d$}–{:.d$}]",
        stat.median,
        stat.min,
        stat.max,
        d = decimals
    )
}

impl PerfReport {
    /// A run saved with `raycheck perf --json`.
    pub fn load(path: &Path) -> anyhow::Result<PerfReport> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the saved run {}", path.display()))?;
        serde_json::from_str(&text).with_context(|| {
            format!(
                "{}: not a run saved by raycheck perf --json (or --save)",
                path.display()
            )
        })
    }

    /// Where, when and how the numbers were measured, for every caption.
    pub fn caption(&self) -> String {
        format!(
            "{} · {} · {}² primary rays per scene · medians of {} interleaved runs after one warm-up build{}, [min–max]",
            self.meta.caption(),
            self.instruction_sets(),
            self.resolution,
            self.runs,
            self.builds_in_a_run()
        )
    }

    /// How many builds each run timed per backend, where it was more than
    /// one: `, a run's build the median of 5 (1 above 1000000 triangles)`.
    fn builds_in_a_run(&self) -> String {
        let rounds = |above: bool| {
            self.rows
                .iter()
                .filter(|r| (r.triangles > REPEATED_BUILDS_UP_TO) == above)
                .map(|r| r.builds_per_run)
                .max()
        };
        match (rounds(false), rounds(true)) {
            (Some(n), None) if n > 1 => format!(", a run's build the median of {n}"),
            (Some(n), Some(m)) if n > 1 => format!(
                ", a run's build the median of {n} ({m} above {REPEATED_BUILDS_UP_TO} triangles)"
            ),
            _ => String::new(),
        }
    }

    /// The instruction sets both sides ran, e.g. `ours: kernel avx512 ·
    /// Embree: isa avx512 (selected, simd256; asked auto)`.
    pub fn instruction_sets(&self) -> String {
        let embree = match self.embree_isa.as_str() {
            "" => "isa not recorded".to_string(),
            "n/a" => "not timed".to_string(),
            selected => format!("isa {selected}"),
        };
        format!("ours: kernel {} · Embree: {embree}", self.kernel)
    }

    /// Where the headline numbers are read: the largest benchmark scene
    /// (not a scale scene) timed, at the most threads, as any row there.
    pub fn headline(&self) -> Option<&PerfRow> {
        self.rows
            .iter()
            .filter(|r| !crate::scene::SCALE_SCENES.contains(&r.scene.as_str()))
            .max_by_key(|r| (r.triangles, r.threads))
    }

    /// The row of `backend` on `scene` at `threads`.
    pub fn row(&self, scene: &str, threads: usize, backend: &str) -> Option<&PerfRow> {
        self.rows
            .iter()
            .find(|r| r.scene == scene && r.threads == threads && r.backend == backend)
    }

    /// Every backend's numbers, a row per scene, thread count and backend.
    pub fn throughput_table(&self) -> Table {
        let mut table = Table::new(
            "Build time and throughput per backend, on the same rays",
            &[
                "scene",
                "triangles",
                "threads",
                "backend",
                "build ms",
                "primary Mrays/s",
                "shadow Mrays/s",
                "diffuse Mrays/s",
                "bytes/tri",
                "peak MiB during build",
            ],
            &self.caption(),
        );
        for r in &self.rows {
            table.push([
                Cell::from(r.scene.as_str()),
                r.triangles.to_string().into(),
                r.threads.to_string().into(),
                r.backend.as_str().into(),
                spread(&r.build_ms, 2).into(),
                spread(&r.mrays_primary, 2).into(),
                spread(&r.mrays_shadow, 2).into(),
                spread(&r.mrays_diffuse, 2).into(),
                r.bytes_per_tri
                    .map_or_else(Cell::not_applicable, |b| format!("{b:.0}").into()),
                r.peak_build_mib
                    .map_or_else(Cell::not_applicable, |m| format!("{m:.1}").into()),
            ]);
        }
        table
    }

    /// Every other backend's speed as a ratio to `baseline`'s, a row per
    /// scene, thread count and backend; ours is toned against its goals.
    pub fn ratio_table(&self, goals: &Goals) -> Option<Table> {
        let baseline = goals.baseline.to_string();
        if !self.backends.contains(&baseline) {
            return None;
        }
        let ours = OURS.to_string();
        let mut table = Table::new(
            &format!(
                "Speed relative to {baseline} (above 1 is faster; bytes below 1 is smaller). Goals for ours: build ≥ {}, primary ≥ {}, shadow ≥ {}, diffuse ≥ {}, bytes ≤ {}",
                goals.minimum[0],
                goals.minimum[1],
                goals.minimum[2],
                goals.minimum[3],
                goals.maximum_bytes
            ),
            &[
                "scene",
                "triangles",
                "threads",
                "backend",
                "build",
                "primary",
                "shadow",
                "diffuse",
                "bytes/tri",
            ],
            &self.caption(),
        );
        for r in self.rows.iter().filter(|r| r.backend != baseline) {
            let Some(base) = self.row(&r.scene, r.threads, &baseline) else {
                continue;
            };
            let ratios = r.ratios(base);
            let is_ours = r.backend == ours;
            let tone = |met: bool| match (is_ours, met) {
                (false, _) => Tone::Plain,
                (true, true) => Tone::Good,
                (true, false) => Tone::Bad,
            };
            let mut row = vec![
                Cell::from(r.scene.as_str()),
                r.triangles.to_string().into(),
                r.threads.to_string().into(),
                r.backend.as_str().into(),
            ];
            row.extend(
                ratios[..4]
                    .iter()
                    .zip(goals.minimum)
                    .map(|(&x, goal)| Cell::new(format!("{x:.2}"), tone(x >= goal))),
            );
            row.push(if ratios[4].is_nan() {
                Cell::not_applicable()
            } else {
                Cell::new(
                    format!("{:.2}", ratios[4]),
                    tone(ratios[4] <= goals.maximum_bytes),
                )
            });
            table.push(row);
        }
        Some(table)
    }

    /// One scaling table per thread count: per backend, build time and time
    /// per primary ray against the triangle count, with fitted exponents.
    pub fn scaling_tables(&self) -> Vec<Table> {
        let mut thread_counts: Vec<usize> = self.scaling.iter().map(|s| s.threads).collect();
        thread_counts.dedup();
        thread_counts
            .into_iter()
            .map(|threads| {
                let mut table = Table::new(
                    &format!(
                        "Scaling on {threads} thread(s): exponent k of time ≈ c·n^k, fitted over every scene"
                    ),
                    &["backend", "build time ~ n^k", "time per primary ray ~ n^k", "scenes"],
                    &self.caption(),
                );
                for s in self.scaling.iter().filter(|s| s.threads == threads) {
                    table.push([
                        s.backend.clone(),
                        scaling::exponent_text(s.build_exponent),
                        scaling::exponent_text(s.ns_per_ray_exponent),
                        s.points.len().to_string(),
                    ]);
                }
                table
            })
            .collect()
    }

    /// Every table: throughput, the ratios against each Embree baseline
    /// measured, and the scaling.
    pub fn tables(&self) -> Vec<Table> {
        let mut tables = vec![self.throughput_table()];
        tables.extend(GOALS.iter().filter_map(|g| self.ratio_table(g)));
        tables.extend(self.scaling_tables());
        tables
    }

    /// The tables as Markdown.
    pub fn markdown(&self) -> String {
        let tables: Vec<String> = self.tables().iter().map(Table::to_markdown).collect();
        tables.join("\n")
    }

    /// The tables as a Markdown page, headed by the run's stamp and the
    /// command that made it.
    pub fn markdown_page(&self) -> String {
        format!(
            "# raycheck perf\n\n_{}_\n\nMade by `raycheck perf --backends {}`{}; every number the median of \
             {} runs with its range.\n\n{}",
            self.caption(),
            self.backends.join(","),
            if self.rows.iter().all(|r| r.threads == self.meta.threads) {
                format!(" --threads {}", self.meta.threads)
            } else {
                String::new()
            },
            self.runs,
            self.markdown()
        )
    }

    /// The tables as aligned text for the terminal.
    pub fn text(&self) -> String {
        let tables: Vec<String> = self.tables().iter().map(Table::to_text).collect();
        tables.join("\n")
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{report, row};
    use super::measure::builds_per_run;

    /// The caption says how many builds a run timed, and where that
    /// changes with the scene's size; a run saved before builds were
    /// repeated says nothing of it.
    #[test]
    fn the_caption_names_the_builds_a_run_timed() {
        let sized = |triangles: usize| {
            let mut r = row("s", "ours", 1.0, &[1.0]);
            r.triangles = triangles;
            r.builds_per_run = builds_per_run(triangles);
            r
        };
        let small = report(vec![sized(3_936)], "d", "c").caption();
        assert!(
            small.contains("after one warm-up build, a run's build the median of 5, [min–max]"),
            "{small}"
        );
        let both = report(vec![sized(3_936), sized(13_942_624)], "d", "c").caption();
        assert!(
            both.contains("a run's build the median of 5 (1 above 1000000 triangles)"),
            "{both}"
        );
        let saved_before = report(vec![row("s", "ours", 1.0, &[1.0])], "d", "c").caption();
        assert!(
            saved_before.contains("after one warm-up build, [min–max]"),
            "{saved_before}"
        );
    }
}

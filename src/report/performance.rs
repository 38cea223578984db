//! The report's performance section: the course table of every scene
//! (median, SAH and wide builds of ours beside Embree MEDIUM and ROBUST,
//! warmed up, medians of several runs), the throughput and ratio tables of
//! `raycheck perf`, the scaling of build time and time per ray with the
//! triangle count as log-log plots, and the history of saved runs.

use super::ReportData;
use super::measure::{SceneMeasurements, course_backends};
use super::plot::{Mark, Plot, Scale, Series};
use super::section::Section;
use crate::backends::embree::EMBREE;
use crate::backends::ours::OURS;
use crate::perf::PerfReport;
use crate::perf::baseline::unlike;
use crate::perf::measure::Stat;
use crate::perf::scaling::{Scaling, ScalingPoint};
use crate::results::Table;
use std::path::Path;

const INTRO: &str = "How fast each backend builds and traces, measured side by side in one \
process on the same rays, same thread count, runs interleaved and warmed up, with the median \
and the range of the runs. The course table times whole renders; the throughput table times \
fixed ray sets (primary, shadow, diffuse); the ratio tables hold ours (and each crate) against \
Embree MEDIUM and against MEDIUM + ROBUST, the like-for-like rival of a watertight tracer, \
toned against our goals. Look at the ratio tables' primary and shadow columns.";

/// Builds the section from the scenes' course-table rows, `perf`'s
/// measurements and the saved runs, saving the plots under `images`.
pub fn section(images: &Path, data: &ReportData) -> anyhow::Result<Section> {
    let caption = data.meta.caption();
    let perf = &data.performance;
    let mut section = Section::new("performance", "Performance", INTRO);
    section.subheading("Course table: whole renders");
    for s in &data.scenes {
        section.table(&course_table(s, &caption));
    }
    section.table(&profile_table(&data.scenes, &caption));
    section.subheading("Ray sets, side by side");
    for table in perf.tables() {
        section.table(&table);
    }
    for (name, plot, what) in scaling_plots(perf) {
        section.figure(images, &name, &plot, &what)?;
    }
    section.subheading("History of saved runs");
    match history_plot(&data.history) {
        Some(plot) => section.figure(
            images,
            "history.svg",
            &plot,
            "Our primary-ray throughput over Embree MEDIUM's, per saved run (oldest left) and \
             scene, at the most threads each run measured, over the runs made on the newest \
             run's machine with its kernel and Embree ISA: a drop that stays is a regression; \
             raycheck perf --baseline FILE tells it from noise.",
        )?,
        None => section.paragraph(
            "No saved runs: save one with raycheck perf --json perf-history/NAME.json, and the \
             next report plots every run in perf-history/ (or the folder --history names) over \
             its commits.",
        ),
    }
    Ok(section.finish())
}

/// Where each scene's render time goes, ours against Embree, with the
/// ratio of whole renders beside the ratio of their tracing alone, our
/// render against what our tracing predicts (this backend's render with
/// its tracing time swapped for ours, [`with_tracing`](crate::render::profile::RenderProfile::with_tracing)),
/// and the load the split was measured under.
fn profile_table(scenes: &[SceneMeasurements], caption: &str) -> Table {
    let renders = scenes.first().map_or(0, |s| s.split_renders);
    let mut table = Table::new(
        &format!(
            "Where render time goes: the render timed whole, its own queries replayed alone (tracing), the rest of the radiance (shading and sampling), and bloom with the conversion to 8-bit (image); each the median of {renders} renders, the backends taking turns. The report's own workers hold the one-minute load average near the thread count; a core or more above it, other work shared the cores, which slows the queries timed among the shading more than the same queries replayed alone: the last columns then read high"
        ),
        &[
            "scene",
            "backend",
            "queries",
            "render ms",
            "tracing ms",
            "shading & sampling ms",
            "image ms",
            "render time, ours / this (above 1: ours slower)",
            "tracing time, ours / this",
            "render, ours / predicted by our tracing",
            "load average (1 min) as the split ended",
        ],
        caption,
    );
    for s in scenes {
        let Some((_, ours)) = s.profiles.first() else {
            continue;
        };
        for (name, p) in &s.profiles {
            table.push([
                s.scene.clone(),
                name.clone(),
                p.queries.to_string(),
                format!("{:.1}", p.total_ms),
                format!("{:.1}", p.tracing_ms),
                format!("{:.1}", p.shading_ms),
                format!("{:.1}", p.image_ms),
                format!("{:.2}", ours.total_ms / p.total_ms),
                format!("{:.2}", ours.tracing_ms / p.tracing_ms),
                format!("{:.2}", ours.total_ms / p.with_tracing(ours.tracing_ms)),
                s.split_load_average
                    .map_or_else(|| "unknown".to_string(), |[one, ..]| format!("{one:.2}")),
            ]);
        }
    }
    table
}

/// The runs saved in `folder` (every `.json`), oldest first; none when
/// the folder is not given or does not exist.
pub fn history(folder: Option<&Path>) -> anyhow::Result<Vec<PerfReport>> {
    let Some(folder) = folder.filter(|f| f.is_dir()) else {
        return Ok(Vec::new());
    };
    let mut runs = Vec::new();
    for entry in std::fs::read_dir(folder)? {
        let path = entry?.path();
        if path.extension().is_some_and(|e| e == "json") {
            runs.push(PerfReport::load(&path)?);
        }
    }
    runs.sort_by(|a, b| a.meta.date.cmp(&b.meta.date));
    Ok(runs)
}

/// Ours over Embree MEDIUM on primary rays, one line per scene, one point
/// per saved run like the newest (the same machine, our kernel, Embree's
/// ISA and binding, as `perf --baseline` tells them: a ratio from another
/// measures that too); `None` without saved runs.
fn history_plot(runs: &[PerfReport]) -> Option<Plot> {
    let newest = runs.last()?;
    let saved = runs.len();
    let runs: Vec<&PerfReport> = runs
        .iter()
        .filter(|run| unlike(run, newest).is_empty())
        .collect();
    let ours = OURS.to_string();
    let embree = EMBREE.to_string();
    let mut scenes: Vec<String> = runs
        .iter()
        .flat_map(|r| r.rows.iter().map(|row| row.scene.clone()))
        .collect();
    scenes.sort();
    scenes.dedup();
    let series = scenes
        .iter()
        .map(|scene| Series {
            name: scene.clone(),
            points: runs
                .iter()
                .enumerate()
                .filter_map(|(i, run)| {
                    let threads = run.rows.iter().map(|r| r.threads).max()?;
                    let row = run.row(scene, threads, &ours)?;
                    let base = run.row(scene, threads, &embree)?;
                    Some((i as f64 + 1.0, row.ratios(base)[1]))
                })
                .collect(),
            mark: Mark::LineAndPoints,
        })
        .collect();
    let commits: Vec<String> = runs.iter().map(|r| r.meta.commit.clone()).collect();
    Some(Plot {
        title: "Primary rays, ours / Embree MEDIUM, per saved run".into(),
        x_label: format!("saved run (commits {})", commits.join(", ")),
        y_label: "speed ratio".into(),
        x_scale: Scale::Count,
        y_scale: Scale::Linear,
        series,
        caption: format!(
            "{} · {} of {saved} saved runs, those like this one",
            newest.meta.caption(),
            runs.len()
        ),
    })
}

/// What the tree columns of the course table compare.
const TREE_NOTE: &str = "Our median and SAH trees are binary, built on one thread; \
ours (wide) and Embree's are wider, with several triangles per leaf block, built \
on every thread, so levels, nodes and SAH cost compare tree shapes, not quality";

/// `median [min–max]` in ms.
fn ms(stat: &Stat) -> String {
    format!("{:.1} [{:.1}–{:.1}]", stat.median, stat.min, stat.max)
}

/// The classic course table of one scene: every course backend's build
/// and render time and tree statistics.
pub fn course_table(s: &SceneMeasurements, caption: &str) -> Table {
    let mut table = Table::new(
        &format!(
            "{}: build and render, {}×{} (passes: {}; one warm-up, then the median of {} runs [min–max])",
            s.scene, s.resolution, s.resolution, s.passes, s.runs
        ),
        &[
            "backend",
            "triangles",
            "build ms",
            "render ms",
            "BVH levels",
            "max tris/leaf",
            "nodes",
            "bytes",
            "SAH cost",
        ],
        &format!("{caption}. {TREE_NOTE}"),
    );
    let opt = |v: Option<String>| v.unwrap_or_else(|| "n/a".into());
    for name in course_backends() {
        let Some(row) = s.backend(&name.to_string()) else {
            continue;
        };
        table.push([
            row.backend.clone(),
            s.triangles.to_string(),
            ms(&row.build_ms),
            ms(&row.render_ms),
            opt(row.levels.map(|v| v.to_string())),
            row.max_leaf_triangles.clone(),
            opt(row.nodes.map(|v| v.to_string())),
            opt(row.bytes.map(|v| v.to_string())),
            opt(row.sah_cost.map(|v| format!("{v:.2}"))),
        ]);
    }
    table
}

/// Log-log plots of build time and of time per primary ray against the
/// triangle count, one series per backend with its fitted exponent in the
/// legend; one pair per thread count, each with what it shows.
pub fn scaling_plots(perf: &PerfReport) -> Vec<(String, Plot, String)> {
    let caption = perf.meta.caption();
    let mut thread_counts: Vec<usize> = perf.scaling.iter().map(|s| s.threads).collect();
    thread_counts.dedup();
    let mut plots = Vec::new();
    for threads in thread_counts {
        let scalings: Vec<&Scaling> = perf
            .scaling
            .iter()
            .filter(|s| s.threads == threads)
            .collect();
        let figure = |what: &str,
                      unit: &str,
                      y: fn(&ScalingPoint) -> f64,
                      k: fn(&Scaling) -> Option<f64>| {
            against_triangles(
                format!("{what} against triangles, {threads} thread(s)"),
                unit,
                &scalings,
                |s| match k(s) {
                    Some(k) => format!("{}, n^{k:.2}", s.backend),
                    None => s.backend.clone(),
                },
                |p| Some(y(p)),
                &caption,
            )
        };
        plots.push((
            format!("scaling-build-{threads}t.svg"),
            figure(
                "Build time",
                "build ms",
                |p| p.build_ms,
                |s| s.build_exponent,
            ),
            format!(
                "Build time against triangles on {threads} thread(s), log-log, medians: a slope \
                 (the exponent in the legend) a little above 1 is n log n; the lower line builds \
                 faster."
            ),
        ));
        plots.push((
            format!("scaling-ray-{threads}t.svg"),
            figure(
                "Time per primary ray",
                "ns per ray",
                |p| p.ns_per_ray,
                |s| s.ns_per_ray_exponent,
            ),
            format!(
                "Time per primary ray against triangles on {threads} thread(s), log-log, from \
                 the median throughput: a BVH grows as log n, a small exponent; the lower line \
                 traces faster."
            ),
        ));
    }
    plots.extend(memory_plots(perf));
    plots
}

/// A log-log plot of `y` against the triangle count, a series named
/// `name` per backend's scaling; points without a value, and series
/// without points, are left out.
fn against_triangles(
    title: String,
    unit: &str,
    scalings: &[&Scaling],
    name: impl Fn(&Scaling) -> String,
    y: impl Fn(&ScalingPoint) -> Option<f64>,
    caption: &str,
) -> Plot {
    Plot {
        title,
        x_label: "triangles".into(),
        y_label: unit.into(),
        x_scale: Scale::Log10,
        y_scale: Scale::Log10,
        series: scalings
            .iter()
            .map(|s| Series {
                name: name(s),
                points: s
                    .points
                    .iter()
                    .filter_map(|p| Some((p.triangles as f64, y(p)?)))
                    .collect(),
                mark: Mark::LineAndPoints,
            })
            .filter(|series| !series.points.is_empty())
            .collect(),
        caption: caption.into(),
    }
}

/// Bytes per triangle of the structure built, and the peak memory a build
/// takes, against the triangle count, on the most threads measured.
fn memory_plots(perf: &PerfReport) -> Vec<(String, Plot, String)> {
    let threads = perf.scaling.iter().map(|s| s.threads).max().unwrap_or(1);
    let scalings: Vec<&Scaling> = perf
        .scaling
        .iter()
        .filter(|s| s.threads == threads)
        .collect();
    let caption = perf.meta.caption();
    let plot = |title: &str, unit: &str, y: fn(&ScalingPoint) -> Option<f64>| {
        against_triangles(
            format!("{title} against triangles"),
            unit,
            &scalings,
            |s| s.backend.clone(),
            y,
            &caption,
        )
    };
    vec![
        (
            "scaling-bytes.svg".into(),
            plot("Bytes per triangle", "bytes per triangle", |p| {
                p.bytes_per_tri
            }),
            "The memory each backend's structure holds per triangle (Embree's as its memory \
             monitor sees the scene allocate, its copies of the vertices and indices \
             included): flat lines are memory linear in the triangles; lower is smaller."
                .into(),
        ),
        (
            "scaling-peak.svg".into(),
            plot("Peak memory during a build", "MiB", |p| p.peak_build_mib),
            format!(
                "How far the process's resident memory rose while each backend built, on \
                 {threads} thread(s), medians: the build's own scratch memory beside what it \
                 keeps; a slope of 1 on these log-log axes is linear in the triangles."
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perf::fixtures::{report, row};

    const RUNS: [f64; 3] = [1.0, 1.01, 0.99];

    #[test]
    fn saved_runs_are_read_oldest_first_and_those_like_the_newest_plotted_per_scene() {
        let dir = tempfile::tempdir().unwrap();
        let run = |ours: f64, date: &str, commit: &str| {
            report(
                vec![
                    row("dragon", "ours", ours, &RUNS),
                    row("dragon", "embree", 1.0, &RUNS),
                ],
                date,
                commit,
            )
        };
        // Written newest first: the history sorts them by date.
        // Between them, a run on another machine: its ratio measures the
        // machine too, so the plot leaves it out.
        let mut elsewhere = run(2.0, "2026-11-27 12:00 UTC", "ccc");
        elsewhere.meta.machine = "another CPU".into();
        for (name, saved) in [
            ("b.json", run(1.2, "2026-11-28 10:00 UTC", "bbb")),
            ("c.json", elsewhere),
            ("a.json", run(0.6, "2026-11-27 10:00 UTC", "aaa")),
        ] {
            std::fs::write(
                dir.path().join(name),
                serde_json::to_string(&saved).unwrap(),
            )
            .unwrap();
        }
        std::fs::write(dir.path().join("notes.txt"), "not a run").unwrap();
        let runs = history(Some(dir.path())).unwrap();
        assert_eq!(runs.len(), 3);
        let plot = history_plot(&runs).unwrap();
        assert_eq!(plot.series.len(), 1);
        let points = &plot.series[0].points;
        assert_eq!(points.len(), 2);
        assert!((points[0].1 - 0.6).abs() < 1e-9 && (points[1].1 - 1.2).abs() < 1e-9);
        assert!(plot.x_label.contains("aaa, bbb"), "{}", plot.x_label);
        assert!(
            plot.caption.contains("2 of 3 saved runs"),
            "{}",
            plot.caption
        );
        assert!(
            history(Some(&dir.path().join("missing")))
                .unwrap()
                .is_empty()
        );
        assert!(history_plot(&[]).is_none());
    }
}

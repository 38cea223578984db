//! The report's performance section: the course table of every scene
//! (median, SAH and wide builds of ours beside Embree MEDIUM and ROBUST,
//! warmed up, medians of several runs), the throughput and ratio tables of
//! `raycheck perf`, and the scaling of build time and time per ray with
//! the triangle count as log-log plots.

use super::measure::{COURSE_BACKENDS, SceneMeasurements};
use super::plot::{Mark, Plot, Scale, Series};
use super::section::Section;
use crate::perf::PerfReport;
use crate::perf::measure::Stat;
use crate::perf::scaling::{Scaling, ScalingPoint};
use crate::results::Table;
use std::path::Path;

/// Builds the section from the scenes' course-table rows and `perf`'s
/// measurements, saving the scaling plots under `images`.
pub fn section(
    images: &Path,
    scenes: &[SceneMeasurements],
    perf: &PerfReport,
    caption: &str,
) -> anyhow::Result<Section> {
    let mut section = Section::new("Performance");
    for s in scenes {
        section.table(&course_table(s, caption));
    }
    for table in perf.tables() {
        section.table(&table);
    }
    for (name, plot) in scaling_plots(perf) {
        section.figure(images, &name, &plot, &perf.caption())?;
    }
    Ok(section)
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
    for name in COURSE_BACKENDS {
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
/// legend; one pair per thread count.
pub fn scaling_plots(perf: &PerfReport) -> Vec<(String, Plot)> {
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
        let figure =
            |what: &str, unit: &str, y: fn(&ScalingPoint) -> f64, k: fn(&Scaling) -> f64| Plot {
                title: format!("{what} against triangles, {threads} thread(s)"),
                x_label: "triangles".into(),
                y_label: unit.into(),
                x_scale: Scale::Log10,
                y_scale: Scale::Log10,
                series: scalings
                    .iter()
                    .map(|s| Series {
                        name: format!("{}, n^{:.2}", s.backend, k(s)),
                        points: s
                            .points
                            .iter()
                            .map(|p| (p.triangles as f64, y(p)))
                            .collect(),
                        mark: Mark::LineAndPoints,
                    })
                    .collect(),
                caption: caption.clone(),
            };
        plots.push((
            format!("scaling-build-{threads}t.svg"),
            figure(
                "Build time",
                "build ms",
                |p| p.build_ms,
                |s| s.build_exponent,
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
        ));
    }
    plots
}

//! The report's performance section: the course table of every scene with
//! our fast path beside Embree (MEDIUM and ROBUST) and their ratios, the
//! throughput tables of `raycheck perf`, and the scaling of build time and
//! time per ray with the triangle count as log-log plots.

use super::measure::{FAST, MEDIUM_OPTIONS, REFERENCE_OPTIONS, SceneMeasurements, embree_label};
use super::plot::{Mark, Plot, Scale, Series};
use super::section::Section;
use super::table::Table;
use crate::perf::PerfReport;
use crate::perf::scaling::{Scaling, ScalingPoint};
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
    section.table(&course_table(scenes, caption));
    for table in perf.tables() {
        section.table(&table);
    }
    for (name, plot) in scaling_plots(perf) {
        section.figure(images, &name, &plot, &perf.caption())?;
    }
    Ok(section)
}

/// The classic course table for every scene, our fast path against Embree
/// MEDIUM and MEDIUM + ROBUST, with the ratios ours / Embree (below 1 is
/// faster for times).
pub fn course_table(scenes: &[SceneMeasurements], caption: &str) -> Table {
    let (medium, robust) = (
        embree_label(MEDIUM_OPTIONS),
        embree_label(REFERENCE_OPTIONS),
    );
    let mut table = Table::new(
        "Build and render: ours (fast path) against Embree MEDIUM and MEDIUM, ROBUST (one run each)",
        &[
            "scene",
            "triangles",
            "build ms (fast / MEDIUM / ROBUST)",
            "render ms (fast / MEDIUM / ROBUST)",
            "BVH levels (fast / MEDIUM / ROBUST)",
            "max tris/leaf (fast / MEDIUM / ROBUST)",
            "build ratio (vs MEDIUM, ROBUST)",
            "render ratio (vs MEDIUM, ROBUST)",
        ],
        caption,
    );
    for s in scenes {
        let (Some(fast), Some(medium), Some(robust)) =
            (s.backend(FAST), s.backend(&medium), s.backend(&robust))
        else {
            continue;
        };
        let rows = [fast, medium, robust];
        let join =
            |cell: &dyn Fn(&super::measure::BackendRow) -> String| rows.map(cell).join(" / ");
        let levels = |v: Option<u32>| v.map_or("n/a".into(), |l| l.to_string());
        table.push(vec![
            s.scene.clone(),
            s.triangles.to_string(),
            join(&|r| format!("{:.1}", r.build_ms)),
            join(&|r| format!("{:.1}", r.render_ms)),
            join(&|r| levels(r.levels)),
            join(&|r| r.max_leaf_triangles.clone()),
            format!(
                "{:.2}, {:.2}",
                fast.build_ms / medium.build_ms,
                fast.build_ms / robust.build_ms
            ),
            format!(
                "{:.2}, {:.2}",
                fast.render_ms / medium.render_ms,
                fast.render_ms / robust.render_ms
            ),
        ]);
    }
    table
}

/// Log-log plots of build time and of time per primary ray against the
/// triangle count, ours and each Embree configuration, with the fitted
/// exponents in the legend; one pair per thread count.
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
        let Some(ours) = scalings.first() else {
            continue;
        };
        type Axis = (fn(&ScalingPoint) -> f64, fn(&ScalingPoint) -> f64);
        let figure = |what: &str,
                      unit: &str,
                      (our_y, their_y): Axis,
                      exponents: fn(&Scaling) -> (f64, f64)| {
            let points = |s: &Scaling, y: fn(&ScalingPoint) -> f64| {
                s.points
                    .iter()
                    .map(|p| (p.triangles as f64, y(p)))
                    .collect()
            };
            let mut series = vec![Series {
                name: format!("ours, n^{:.2}", exponents(ours).0),
                points: points(ours, our_y),
                mark: Mark::LineAndPoints,
            }];
            series.extend(scalings.iter().map(|s| Series {
                name: format!("Embree {}, n^{:.2}", s.embree, exponents(s).1),
                points: points(s, their_y),
                mark: Mark::LineAndPoints,
            }));
            Plot {
                title: format!("{what} against triangles, {threads} thread(s)"),
                x_label: "triangles".into(),
                y_label: unit.into(),
                x_scale: Scale::Log10,
                y_scale: Scale::Log10,
                series,
                caption: caption.clone(),
            }
        };
        plots.push((
            format!("scaling-build-{threads}t.svg"),
            figure(
                "Build time",
                "build ms",
                (|p| p.build_ms, |p| p.embree_build_ms),
                |s| (s.build_exponent, s.embree_build_exponent),
            ),
        ));
        plots.push((
            format!("scaling-ray-{threads}t.svg"),
            figure(
                "Time per primary ray",
                "ns per ray",
                (|p| p.ns_per_ray, |p| p.embree_ns_per_ray),
                |s| (s.ns_per_ray_exponent, s.embree_ns_per_ray_exponent),
            ),
        ));
    }
    plots
}

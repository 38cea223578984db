//! Writes the report folder: images, `report.md`, `index.html`, `report.json`.

use super::gallery::Gallery;
use super::measure::SceneMeasurements;
use super::meta::RunMeta;
use super::performance;
use super::stability;
use super::table::{Table, escape_html};
use crate::perf::PerfReport;
use crate::stability::CaseResult;
use anyhow::Context;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[derive(Serialize)]
struct ReportJson<'a> {
    meta: &'a RunMeta,
    scenes: &'a [SceneMeasurements],
    gallery: &'a Gallery,
    performance: &'a PerfReport,
    stability: &'a [CaseResult],
}

/// Writes everything under `out`; returns the path of `index.html`.
pub fn write(
    out: &Path,
    meta: &RunMeta,
    scenes: &[SceneMeasurements],
    gallery: &Gallery,
    perf: &PerfReport,
    stability_results: &[CaseResult],
) -> anyhow::Result<PathBuf> {
    let images = out.join("images");
    std::fs::create_dir_all(&images).with_context(|| format!("creating {}", images.display()))?;
    let caption = meta.caption();
    for s in scenes {
        let stamp = |backend: &str| meta.stamp(&format!("{}, {backend}", s.scene));
        let ours = stamp("ours (SAH)");
        let embree = stamp("Embree");
        for ext in ["png", "exr"] {
            let name = format!("{}.{ext}", s.scene);
            s.ours_image.save_stamped(&images.join(name), &ours)?;
            let name = format!("{}-embree.{ext}", s.scene);
            s.embree_image.save_stamped(&images.join(name), &embree)?;
        }
    }
    let summary = agreement_summary(scenes, &caption);
    let mut markdown = format!(
        "# raycheck report\n\n_{caption}_\n\n{}\n",
        summary.to_markdown()
    );
    let mut html = format!(
        "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>raycheck report</title>\n\
         <style>{STYLE}</style></head><body>\n<h1>raycheck report</h1>\n\
         <p class=\"meta\">{}</p>\n{}",
        escape_html(&caption),
        summary.to_html()
    );
    for s in scenes {
        let performance = performance_table(s, &caption);
        let agreement = agreement_table(s, &caption);
        let figure = figure_caption(s, &caption);
        let _ = write!(
            markdown,
            "\n## {name} ({tris} triangles; {features})\n\n{perf}\n\
             ![{name}](images/{name}.png) ![{name} on Embree](images/{name}-embree.png)\n\n\
             _{figure}_\n\n{agree}\n",
            name = s.scene,
            tris = s.triangles,
            features = s.features.join(", "),
            perf = performance.to_markdown(),
            agree = agreement.to_markdown(),
        );
        let _ = write!(
            html,
            "<h2>{name} ({tris} triangles; {features})</h2>\n{perf}\
             <figure><img src=\"images/{name}.png\" alt=\"{name}, ours\">\
             <img src=\"images/{name}-embree.png\" alt=\"{name}, Embree\">\
             <figcaption>{figure}</figcaption></figure>\n{agree}",
            name = escape_html(&s.scene),
            tris = s.triangles,
            features = escape_html(&s.features.join(", ")),
            perf = performance.to_html(),
            figure = escape_html(&figure),
            agree = agreement.to_html(),
        );
    }
    gallery.write_images(&images, meta)?;
    markdown += &gallery.markdown(&caption);
    html += &gallery.html(&caption);
    let performance = performance::section(&images, scenes, perf, &caption)?;
    markdown += &performance.markdown;
    html += &performance.html;
    let stability = stability::section(&images, stability_results, &caption)?;
    markdown += &stability.markdown;
    html += &stability.html;
    html += "</body></html>\n";
    std::fs::write(out.join("report.md"), markdown)?;
    let index = out.join("index.html");
    std::fs::write(&index, html)?;
    let json = serde_json::to_string_pretty(&ReportJson {
        meta,
        scenes,
        gallery,
        performance: perf,
        stability: stability_results,
    })?;
    std::fs::write(out.join("report.json"), json)?;
    Ok(index)
}

const STYLE: &str = "body{font-family:sans-serif;max-width:72em;margin:2em auto}\
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:2px 8px;\
text-align:right}caption{font-weight:bold;text-align:left}.meta{color:#666;font-size:90%}\
img{width:400px;margin-right:8px}img.plot{width:640px}";

/// What the tree columns of the performance table compare.
const TREE_NOTE: &str = "Our trees are binary and built on one thread; Embree's \
is 8-wide with blocks of 4 triangles per leaf and is built on every thread, so \
its levels, nodes and SAH cost are of a different tree shape";

fn performance_table(s: &SceneMeasurements, caption: &str) -> Table {
    let mut table = Table::new(
        &format!(
            "{}: build and render ({}×{}, passes: {}; one run)",
            s.scene, s.resolution, s.resolution, s.passes
        ),
        &[
            "backend",
            "triangles",
            "build (ms)",
            "render (ms)",
            "BVH levels",
            "max tris/leaf",
            "nodes",
            "bytes",
            "SAH cost",
        ],
        &format!("{caption}. {TREE_NOTE}"),
    );
    let opt = |v: Option<String>| v.unwrap_or_else(|| "n/a".into());
    for row in &s.backends {
        table.push(vec![
            row.backend.clone(),
            s.triangles.to_string(),
            format!("{:.1}", row.build_ms),
            format!("{:.1}", row.render_ms),
            opt(row.levels.map(|v| v.to_string())),
            row.max_leaf_triangles.clone(),
            opt(row.nodes.map(|v| v.to_string())),
            opt(row.bytes.map(|v| v.to_string())),
            opt(row.sah_cost.map(|v| format!("{v:.2}"))),
        ]);
    }
    table
}

const AGREEMENT_HEADERS: [&str; 15] = [
    "builder",
    "rays",
    "hit mismatch",
    "prim mismatch",
    "t mismatch",
    "occlusion mismatch",
    "max rel t error",
    "… primary rays",
    "ours_wrong",
    "embree_wrong",
    "ambiguous",
    "ours t off",
    "Embree t off",
    "hit agreement",
    "prim agreement",
];

fn agreement_row(label: &str, c: &crate::check::CompareSummary) -> Vec<String> {
    vec![
        label.to_string(),
        c.rays.to_string(),
        c.hit_mismatch.to_string(),
        c.prim_mismatch.to_string(),
        c.t_mismatch.to_string(),
        c.occlusion_mismatch.to_string(),
        format!("{:.2e}", c.max_rel_t_error),
        format!("{:.2e}", c.max_rel_t_error_primary),
        c.ours_wrong.to_string(),
        c.embree_wrong.to_string(),
        c.ambiguous.to_string(),
        c.ours_t_off.to_string(),
        c.embree_t_off.to_string(),
        format!("{:.5}%", 100.0 * c.hit_agreement),
        format!("{:.4}%", 100.0 * c.prim_agreement),
    ]
}

fn agreement_table(s: &SceneMeasurements, caption: &str) -> Table {
    let mut table = Table::new(
        &format!("{}: agreement with Embree (MEDIUM, ROBUST)", s.scene),
        &AGREEMENT_HEADERS,
        caption,
    );
    for (builder, c) in &s.agreement {
        table.push(agreement_row(builder, c));
    }
    table
}

fn agreement_summary(scenes: &[SceneMeasurements], caption: &str) -> Table {
    let mut headers = vec!["scene", "triangles"];
    headers.extend_from_slice(&AGREEMENT_HEADERS);
    let mut table = Table::new(
        "Agreement with Embree 4.4 (MEDIUM, ROBUST), all scenes",
        &headers,
        caption,
    );
    for s in scenes {
        for (builder, c) in &s.agreement {
            let mut row = vec![s.scene.clone(), s.triangles.to_string()];
            row.extend(agreement_row(builder, c));
            table.push(row);
        }
    }
    table
}

fn figure_caption(s: &SceneMeasurements, caption: &str) -> String {
    format!(
        "{name}, {res}×{res}: left ours (SAH), right Embree; {n} pixels differ, by at most {d:.2e} (linear). {caption}",
        name = s.scene,
        res = s.resolution,
        n = s.differing_pixels,
        d = s.max_pixel_difference,
    )
}

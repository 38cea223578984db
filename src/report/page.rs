//! Writes the report folder: images, `report.md`, `index.html`, `report.json`.

use super::gallery::Gallery;
use super::measure::{SceneMeasurements, image_difference};
use super::performance;
use super::stability;
use crate::perf::PerfReport;
use crate::results::RunMeta;
use crate::results::table::{Cell, Table, escape_html};
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
        let ours = stamp("ours");
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
        let agreement = s.agreement.table(&caption);
        let figure = figure_caption(s, &caption);
        let _ = write!(
            markdown,
            "\n## {name} ({tris} triangles; {features})\n\n\
             ![{name}](images/{name}.png) ![{name} on Embree](images/{name}-embree.png)\n\n\
             _{figure}_\n\n{agree}\n",
            name = s.scene,
            tris = s.triangles,
            features = s.features.join(", "),
            agree = agreement.to_markdown(),
        );
        let _ = write!(
            html,
            "<h2>{name} ({tris} triangles; {features})</h2>\n\
             <figure><img src=\"images/{name}.png\" alt=\"{name}, ours\">\
             <img src=\"images/{name}-embree.png\" alt=\"{name}, Embree\">\
             <figcaption>{figure}</figcaption></figure>\n{agree}",
            name = escape_html(&s.scene),
            tris = s.triangles,
            features = escape_html(&s.features.join(", ")),
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
.table-scroll{overflow-x:auto}td.good{background:#e3f4e3}td.bad{background:#f8d7d3}\
td.warn{background:#fcf0cc}td.na{color:#888}\
img{width:400px;margin-right:8px}img.plot{width:640px}";

/// Every scene's verdicts per backend, in one table.
fn agreement_summary(scenes: &[SceneMeasurements], caption: &str) -> Table {
    let mut table = Table::new(
        "The compare ray sets of every scene, judged exactly: wrong answers per backend, in rays",
        &[
            "scene",
            "triangles",
            "rays",
            "judged",
            "ambiguous",
            "backend",
            "wrong",
            "t off",
            "NaN outputs",
        ],
        caption,
    );
    for s in scenes {
        let v = &s.agreement.verdicts;
        for b in &v.backends {
            table.push([
                Cell::from(s.scene.as_str()),
                s.triangles.to_string().into(),
                v.rays.to_string().into(),
                v.judged.to_string().into(),
                v.ambiguous.to_string().into(),
                b.name.as_str().into(),
                Cell::wrong_count(b.wrong),
                Cell::wrong_count(b.t_off),
                Cell::wrong_count(b.nan_outputs),
            ]);
        }
    }
    table
}

fn figure_caption(s: &SceneMeasurements, caption: &str) -> String {
    let (differing, largest) = image_difference(&s.ours_image, &s.embree_image);
    format!(
        "{name}, {res}×{res}: left ours, right Embree; {differing} pixels differ, by at most {largest:.2e} (linear). {caption}",
        name = s.scene,
        res = s.resolution,
    )
}
